#include "render/transparent_walk.h"

#include "geometry/offset_ray.h"

#include <cmath>

namespace toyrt {

CrossedSurface crossed_surface(const Scene& scene, const Hit& hit) {
  const Instance& inst = scene.instance(uint32_t(hit.instance));
  const Mesh& mesh = scene.mesh(inst.mesh);
  const Triangle& tri = mesh.triangles()[size_t(hit.prim)];
  const Vec3 p0 = mesh.vertices()[tri.x], p1 = mesh.vertices()[tri.y], p2 = mesh.vertices()[tri.z];
  const float w = 1.0f - hit.u - hit.v;
  CrossedSurface s;
  const Vec3 local = w * p0 + hit.u * p1 + hit.v * p2;
  s.p = inst.identity ? local : Vec3(inst.to_world * glm::vec4(local, 1.0f));
  // Normals transform by the inverse transpose; the inverse is the instance's to_object.
  s.ng = glm::normalize(glm::transpose(glm::mat3(inst.to_object)) * glm::cross(p1 - p0, p2 - p0));
  const MeshShading& sh = scene.shading(inst.mesh);
  const size_t c = 3 * size_t(hit.prim);
  if (!sh.corner_uvs.empty()) s.uv = w * sh.corner_uvs[c] + hit.u * sh.corner_uvs[c + 1] + hit.v * sh.corner_uvs[c + 2];
  if (!sh.material_ids.empty()) s.material = sh.material_ids[size_t(hit.prim)];
  return s;
}

Ray continue_through(const Ray& ray, const Vec3& at, const Vec3& ng, TriangleRef crossed) {
  const Vec3 origin = offset_ray_origin(at, glm::dot(ng, ray.dir) > 0.0f ? ng : -ng);
  if (std::isinf(ray.tfar)) return Ray{origin, 0.0f, ray.dir, kInfinity, crossed};
  const Vec3 to_end = ray.org + ray.dir * ray.tfar - origin;
  // Past the end (the surface lay at the ray's very end): nothing is left to trace.
  if (glm::dot(to_end, ray.dir) <= 0.0f) return Ray{origin, 1.0f, ray.dir, 0.0f, crossed};
  return Ray{origin, 0.0f, to_end, 1.0f, crossed};
}

Vec3 transmittance_walk(const Scene& scene, const Ray& ray, int budget, bool casters_only, uint64_t blockers,
                        uint8_t seen_by) {
  // Light arrives when the walk ends without meeting an opaque surface (or one cut-out too many).
  Vec3 tr(1.0f);
  return walk_to_opaque(scene, ray, budget, tr, casters_only, blockers, seen_by).found() ? Vec3(0.0f) : tr;
}

Hit walk_to_opaque(const Scene& scene, Ray ray, int budget, Vec3& tr, bool casters_only, uint64_t blockers,
                   uint8_t seen_by) {
  const std::vector<MaterialTransparency>& table = scene.transparency();
  for (int crossed = 0;; ++crossed) {
    if (ray.tnear > ray.tfar) return Hit{};
    const Hit hit = casters_only ? scene.intersect_shadow_casters(ray, blockers) : scene.intersect(ray, seen_by);
    if (!hit.found()) return hit;
    const CrossedSurface s = crossed_surface(scene, hit);
    if (s.material < 0 || size_t(s.material) >= table.size() || !table[size_t(s.material)].transparent()) return hit;
    // One transparent surface more than the budget blocks, as in Cycles; so does one that lets
    // nothing through.
    const MaterialTransparency& t = table[size_t(s.material)];
    if (crossed >= budget) {
      tr = Vec3(0.0f);
      return hit;
    }
    tr *= (1.0f - t.opacity_at(scene.textures(), s.uv)) * t.color;
    if (tr == Vec3(0.0f)) return hit;
    ray = continue_through(ray, s.p, s.ng, TriangleRef{hit.prim, hit.instance});
  }
}

bool passes_through(const Scene& scene, const MaterialTransparency& t, const Vec2& uv, float u, Vec3& throughput) {
  const float o = t.opacity_at(scene.textures(), uv);
  const Vec3 through = (1.0f - o) * t.color;
  const float w = (through.x + through.y + through.z) / 3.0f;
  const float p = w > 0.0f ? w / (w + o) : 0.0f;
  if (u < p) {
    throughput *= through / p;
    return true;
  }
  throughput *= o / (1.0f - p);
  return false;
}

}  // namespace toyrt
