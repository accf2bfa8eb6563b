// Point queries against the closed meshes of a committed scene (Open3D's compute_occupancy,
// compute_closest_points, compute_distance, compute_signed_distance). Points are (count, 3)
// row-major floats in world space; every point must be finite (std::invalid_argument names the
// first that is not, before any work). Results do not depend on the thread count.
#pragma once

#include "scene/scene.h"

#include <cstdint>

namespace toyrt::queries {

// Inside (1) or outside (0) for each point. Per instance whose world box contains the point
// (closed box): a point exactly on one of the instance's triangles (an exact test) is inside;
// otherwise the point is inside when the ray from it along world +x crosses the instance's mesh
// an odd number of times (the exact crossings of queries/exact_crossing.h, t > 0). A point is
// inside the scene when it is inside any instance (the union of the solids). For a closed mesh
// this is the exact inside test (of the mesh placed by the float transform); an open mesh gets
// the parity of that one +x ray, which is defined but depends on the direction.
void compute_occupancy(const Scene& scene, const float* points, size_t count, uint8_t* inside, int threads = 0);

// The nearest surface point of each query point, searched in world space in double precision
// (instances' triangles are transformed in double, BVH boxes pruned by their distance). With no
// triangle in the scene, distance is inf, the ids -1 and point, u, v, normal NaN.
struct ClosestBatch {
  float* points = nullptr;    // (count, 3): the closest point
  float* distance = nullptr;  // (count,): to it, rounded once from double
  int32_t* mesh = nullptr;
  int32_t* instance = nullptr;
  int32_t* prim = nullptr;
  float* u = nullptr;  // closest = (1 - u - v) p0 + u p1 + v p2
  float* v = nullptr;
  float* normal = nullptr;  // (count, 3): the triangle's unit geometric normal in world space
};
void compute_closest_points(const Scene& scene, const float* points, size_t count, const ClosestBatch& out,
                            int threads = 0);

// Distances only; signed: negative where compute_occupancy says inside (0 on the surface).
void compute_distance(const Scene& scene, const float* points, size_t count, float* distance, bool signed_distance,
                      int threads = 0);

// The shared check of the point queries: throws std::invalid_argument naming the first
// non-finite point.
void check_points(const float* points, size_t count);

}  // namespace toyrt::queries
