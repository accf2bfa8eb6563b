// Scene::gather_emitters: the emissive triangles of every placed instance, in world space.
#include "scene/scene.h"

#include <algorithm>
#include <cmath>

namespace toyrt {

namespace {

// The mean of a texture's texels (at most ~1M of them, evenly strided).
Vec3 texture_mean(const Texture& t) {
  const int step = std::max(1, int(std::sqrt(double(t.width) * double(t.height) / 1.0e6)));
  Vec3 sum(0.0f);
  double count = 0.0;
  for (int y = 0; y < t.height; y += step)
    for (int x = 0; x < t.width; x += step) {
      sum += Vec3(t.texel(x, y));
      count += 1.0;
    }
  return count > 0.0 ? sum / float(count) : Vec3(0.0f);
}

}  // namespace

Vec2 Scene::emitter_uv(uint64_t key, const Vec2& b) const {
  const Instance& inst = instances_[size_t(key >> 32)];
  const MeshShading& sh = shading_[inst.mesh];
  const size_t c = 3 * size_t(key & 0xffffffffu);
  if (sh.corner_uvs.size() < c + 3) return Vec2(0.0f);
  return (1.0f - b.x - b.y) * sh.corner_uvs[c] + b.x * sh.corner_uvs[c + 1] + b.y * sh.corner_uvs[c + 2];
}

Vec3 Scene::emitted_at(uint64_t key, const Vec2& b) const {
  const Instance& inst = instances_[size_t(key >> 32)];
  const MeshShading& sh = shading_[inst.mesh];
  const size_t t = size_t(key & 0xffffffffu);
  if (t >= sh.material_ids.size()) return Vec3(0.0f);
  const MaterialEmission& e = emission_[size_t(sh.material_ids[t])];
  return emitted(e, textures_, emitter_uv(key, b));
}

void Scene::gather_emitters() {
  emitters_ = MeshEmitters{};
  if (std::none_of(emission_.begin(), emission_.end(),
                   [](const MaterialEmission& e) { return e.emits() && e.sampled; }))
    return;                                                // a scene without sampled emitters pays nothing here
  std::vector<Vec3> means(textures_.size(), Vec3(-1.0f));  // per texture, once some emitter reads it
  for (size_t i = 0; i < instances_.size(); ++i) {
    const Instance& inst = instances_[i];
    // Hidden from diffuse rays: no diffuse surface samples it (Cycles excludes such mesh lights;
    // the diffuse cosine rays pass it too). Camera, glossy and glass rays still see it.
    if (!(inst.visibility & kVisibleDiffuse)) continue;
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
      const uint64_t key = uint64_t(i) << 32 | uint64_t(t);
      if (e.texture >= 0) {
        // Weighed by its pixels: half the image's mean at seven points of the triangle (its
        // corners, edge midpoints and centre), half the whole image's, so a triangle over a dark
        // part is still chosen where its image has any light (its probability must not be 0 where
        // it emits); the sample itself reads the image where it lands.
        Vec3& whole = means[size_t(e.texture)];
        if (whole.x < 0.0f) whole = texture_mean(textures_[size_t(e.texture)]);
        static constexpr float kPoints[7][2] = {
            {0, 0}, {1, 0}, {0, 1}, {0.5f, 0}, {0.5f, 0.5f}, {0, 0.5f}, {1 / 3.0f, 1 / 3.0f}};
        Vec3 local(0.0f);
        for (const auto& q : kPoints) local += emitted_at(key, Vec2(q[0], q[1]));
        et.radiance = 0.5f * (local / 7.0f + e.radiance * whole);
        et.textured = true;
      }
      emitters_.add(et, key);  // ascending: index_of() finds hits by it
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
