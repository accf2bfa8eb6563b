// Meshes and ray sets shared by the C++ tests and the trace benchmark. Everything is generated
// from a seed, so every run sees the same geometry and rays.
#pragma once

#include "core/ray.h"
#include "geometry/mesh.h"
#include "sampling/warp.h"

#include <cstdint>
#include <vector>

namespace toyrt::testing {

struct MeshData {
  std::vector<Vec3> vertices;
  std::vector<Triangle> triangles;
  size_t triangle_count() const { return triangles.size(); }
};

// A square of side 2 half at height z, centred on (x, 0, z), facing up, as side x side quads of two
// triangles; uvs: per vertex, (0, 0) to (1, 1) across the square.
struct GridData {
  MeshData mesh;
  std::vector<Vec2> uvs;
};
GridData square_grid(int side, float x, float z, float half);

// Closed UV sphere with shared vertices: `rings` latitude bands, `segments` longitudes; each
// pole is one vertex shared by a fan of `segments` triangles. 2 * segments * (rings - 1) triangles.
// bumps > 0 modulates the radius, so the surface is not convex and rays see several layers.
MeshData uv_sphere(int rings, int segments, float radius = 1.0f, float bumps = 0.0f);
// A closed double cone: two apex vertices each shared by `segments` triangles around one ring.
MeshData bicone_fan(int segments);
// `count` independent random triangles of size about `size` in the unit cube.
MeshData triangle_soup(size_t count, float size, uint64_t seed);
// Random long thin triangles (aspect ratio about 1e4) in the unit cube.
MeshData slivers(size_t count, uint64_t seed);
// The mesh scaled by `scale` about the origin, then moved by `offset`.
MeshData transformed(const MeshData& mesh, float scale, const Vec3& offset);
BBox bounds_of(const MeshData& mesh);
// The mesh inside a closed box room (12 large triangles, facing inwards) `margin` times the
// mesh's extent on each side: the scene where a shadow ray leaving towards a light outside is
// blocked by a wall, whatever the dense mesh does.
MeshData in_closed_room(const MeshData& mesh, float margin);
// Each triangle's box: what the builders take.
struct PrimitiveBounds {
  std::vector<BBox> boxes;
};
PrimitiveBounds triangle_bounds(const MeshData& mesh);

// Pinhole-camera rays from outside the box looking at its centre, width x height of them.
std::vector<Ray> primary_rays(const BBox& box, int width, int height);
// Rays from points just off the surface at `hits` into a cosine-distributed direction about the
// geometric normal on the side the incoming ray came from (the rays a diffuse bounce shoots),
// or, with `through`, on the far side (a diffuse transmission: inside a closed convex mesh).
std::vector<Ray> diffuse_rays(const MeshData& mesh, const std::vector<Ray>& incoming, const std::vector<Hit>& hits,
                              uint64_t seed, bool through = false);
// Rays from the same surface points to a light position, tfar ending at the light.
std::vector<Ray> shadow_rays(const MeshData& mesh, const std::vector<Ray>& incoming, const std::vector<Hit>& hits,
                             const Vec3& light);
// The rays diffuse_rays or shadow_rays made from `hits` (one for each hit found, in order), each
// with `self` set to the triangle it leaves where it leaves to the side its origin was moved to, as
// a renderer's rays do (Ray::self): every diffuse ray; a shadow ray whose light is on that side.
std::vector<Ray> leaving_their_triangles(const MeshData& mesh, std::vector<Ray> rays, const std::vector<Hit>& hits);
// Rays from `inside` aimed exactly at every vertex, every edge midpoint and `per_edge` random
// points on every edge of the mesh (points computed in float, as a renderer would).
std::vector<Ray> rays_at_vertices_and_edges(const MeshData& mesh, const Vec3& inside, int per_edge, uint64_t seed);

// The surface point and geometric normal (not normalised) of a hit.
Vec3 hit_point(const MeshData& mesh, const Hit& hit);
Vec3 geometric_normal(const MeshData& mesh, int32_t prim);

}  // namespace toyrt::testing
