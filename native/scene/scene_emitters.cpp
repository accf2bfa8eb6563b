// Scene::gather_emitters: the emissive triangles of every placed instance, in world space.
#include "scene/scene.h"

#include <algorithm>
#include <cmath>

namespace toyrt {

void Scene::gather_emitters() {
  emitters_ = MeshEmitters{};
  if (std::none_of(emission_.begin(), emission_.end(),
                   [](const MaterialEmission& e) { return e.emits() && e.sampled; }))
    return;  // a scene without sampled emitters pays nothing here
  for (size_t i = 0; i < instances_.size(); ++i) {
    const Instance& inst = instances_[i];
    const Mesh& mesh = *meshes_[inst.mesh];
    const MeshShading& sh = shading_[inst.mesh];
    const std::vector<Vec3>& v = mesh.vertices();
    const std::vector<Triangle>& tris = mesh.triangles();
    // A mesh without material ids renders with the default grey, which emits nothing.
    if (sh.material_ids.empty()) continue;
    for (size_t t = 0; t < tris.size(); ++t) {
      const size_t mat = size_t(sh.material_ids[t]);
      if (mat >= emission_.size()) continue;
      const MaterialEmission& e = emission_[mat];
      if (!e.emits() || !e.sampled) continue;
      const Vec3 a = Vec3(inst.to_world * glm::vec4(v[tris[t].x], 1.0f));
      const Vec3 b = Vec3(inst.to_world * glm::vec4(v[tris[t].y], 1.0f));
      const Vec3 c = Vec3(inst.to_world * glm::vec4(v[tris[t].z], 1.0f));
      EmissiveTriangle et;
      et.p0 = a;
      et.e1 = b - a;
      et.e2 = c - a;
      const Vec3 n = glm::cross(et.e1, et.e2);
      et.area = 0.5f * glm::length(n);
      if (!(et.area > 0.0f) || !std::isfinite(et.area)) continue;
      et.normal = n / (2.0f * et.area);
      et.radiance = e.radiance;
      et.sides = e.sides;
      emitters_.add(et, uint64_t(i) << 32 | uint64_t(t));  // ascending: index_of() finds hits by it
    }
  }
  // The scene's extent, for the tree's spread test (top_ is built before the emitters are gathered).
  float diagonal = 0.0f;
  if (!top_.nodes.empty()) {
    const float* b = top_.nodes[0].bounds;
    diagonal = glm::length(Vec3(b[3] - b[0], b[4] - b[1], b[5] - b[2]));
  }
  emitters_.finish(emitter_tree_from_, kEmitterLeafSize,
                   std::isfinite(diagonal) ? emitter_tree_spread_ * diagonal : 0.0f);
}

}  // namespace toyrt
