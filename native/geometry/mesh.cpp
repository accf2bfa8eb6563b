#include "geometry/mesh.h"

#include "accel/traverse.h"

#include <stdexcept>
#include <string>

namespace toyrt {
namespace {

bool is_degenerate(const Vec3& p0, const Vec3& p1, const Vec3& p2) {
  if (p0 == p1 || p1 == p2 || p2 == p0) return true;
  const DVec3 n = glm::cross(DVec3(p1) - DVec3(p0), DVec3(p2) - DVec3(p0));
  return n.x == 0.0 && n.y == 0.0 && n.z == 0.0;
}

}  // namespace

Mesh::Mesh(std::vector<Vec3> vertices, std::vector<Triangle> triangles)
    : vertices_(std::move(vertices)), triangles_(std::move(triangles)) {
  if (triangles_.size() >= size_t(INT32_MAX))
    throw std::invalid_argument("a mesh holds at most 2^31 - 1 triangles");
  for (size_t i = 0; i < vertices_.size(); ++i) {
    if (!is_finite(vertices_[i]))
      throw std::invalid_argument("vertex " + std::to_string(i) + " is not finite (NaN or inf)");
    bounds_.extend(vertices_[i]);
  }
  const size_t n = vertices_.size();
  for (size_t i = 0; i < triangles_.size(); ++i) {
    const Triangle& t = triangles_[i];
    if (t.x >= n || t.y >= n || t.z >= n)
      throw std::invalid_argument("triangle " + std::to_string(i) + " indexes a vertex out of range (" +
                                  std::to_string(n) + " vertices)");
  }
}

void Mesh::build(const BinnedSahConfig& config) {
  std::vector<uint32_t> valid;
  valid.reserve(triangles_.size());
  for (size_t i = 0; i < triangles_.size(); ++i) {
    const Triangle& t = triangles_[i];
    if (!is_degenerate(vertices_[t.x], vertices_[t.y], vertices_[t.z])) valid.push_back(uint32_t(i));
  }
  std::vector<BBox> boxes(valid.size());
  std::vector<Vec3> centers(valid.size());
  bounds_ = BBox{};
  for (size_t k = 0; k < valid.size(); ++k) {
    const Triangle& t = triangles_[valid[k]];
    BBox b;
    b.extend(vertices_[t.x]);
    b.extend(vertices_[t.y]);
    b.extend(vertices_[t.z]);
    boxes[k] = b;
    centers[k] = b.center();
    bounds_.extend(b);
  }
  bvh_ = build_binned_sah(boxes.data(), centers.data(), boxes.size(), config);
  // Translate builder slots to triangle indices and copy the vertices into leaf order.
  leaf_triangles_.resize(bvh_.prim_ids.size());
  for (size_t s = 0; s < bvh_.prim_ids.size(); ++s) {
    const uint32_t tri = valid[bvh_.prim_ids[s]];
    const Triangle& t = triangles_[tri];
    bvh_.prim_ids[s] = tri;
    leaf_triangles_[s] = {vertices_[t.x], vertices_[t.y], vertices_[t.z]};
  }
  built_ = true;
}

template <bool AnyHit>
bool Mesh::trace(const Vec3& org, const Vec3& dir, float tnear, float& tfar, float& u, float& v,
                 int32_t& prim) const {
  const RayBoxData box_ray = make_ray_box_data(org, dir);
  const WatertightRay tri_ray = make_watertight_ray(org, dir);
  const TriangleVerts* tris = leaf_triangles_.data();
  uint32_t slot = 0;
  const bool found = traverse<AnyHit>(bvh_, box_ray, tnear, tfar, [&](uint32_t first, uint32_t count, float& t_max) {
    bool hit = false;
    for (uint32_t s = first; s < first + count; ++s) {
      float t, hu, hv;
      if (intersect_triangle(tri_ray, tris[s].p0, tris[s].p1, tris[s].p2, tnear, t_max, t, hu, hv)) {
        t_max = t;
        slot = s;
        hit = true;
        if constexpr (AnyHit) return true;
      }
    }
    return hit;
  });
  if constexpr (!AnyHit) {
    if (found) {
      const TriangleVerts& tri = tris[slot];
      refine_hit(org, dir, tri.p0, tri.p1, tri.p2, tnear, tfar, u, v);
      prim = int32_t(bvh_.prim_ids[slot]);
    }
  }
  return found;
}

bool Mesh::intersect(const Vec3& org, const Vec3& dir, float tnear, float& tfar, float& u, float& v,
                     int32_t& prim) const {
  return trace<false>(org, dir, tnear, tfar, u, v, prim);
}

bool Mesh::occluded(const Vec3& org, const Vec3& dir, float tnear, float tfar) const {
  float u, v;
  int32_t prim;
  return trace<true>(org, dir, tnear, tfar, u, v, prim);
}

size_t Mesh::memory_bytes() const {
  return vertices_.capacity() * sizeof(Vec3) + triangles_.capacity() * sizeof(Triangle) +
         bvh_.nodes.capacity() * sizeof(Node) + bvh_.prim_ids.capacity() * sizeof(uint32_t) +
         leaf_triangles_.capacity() * sizeof(TriangleVerts);
}

}  // namespace toyrt
