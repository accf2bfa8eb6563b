#include "materials/dielectric_albedo.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <mutex>
#include <tuple>

namespace toyrt {
namespace {

float albedo_at(float alpha, float eta, GgxShadowing shadowing, float cos_o) {
  DielectricLobe lobe;
  lobe.wo = Vec3(std::sqrt(std::max(0.0f, 1.0f - cos_o * cos_o)), 0.0f, cos_o);
  lobe.alpha = alpha;
  lobe.eta = eta;
  lobe.shadowing = shadowing;
  lobe.kind = DielectricKind::Glass;
  constexpr int kN = 128;  // 64 left 0.5 % at normal incidence from inside (the grazing normals of the tail)
  double sum = 0.0;
  for (int i = 0; i < kN; ++i) {
    for (int j = 0; j < kN; ++j) {
      const Vec2 u((float(i) + 0.5f) / kN, (float(j) + 0.5f) / kN);
      // u_side 0 takes the reflection, 1 the transmission (when the microfacet refracts); their
      // Fresnel weights are the probabilities the sampler would give them.
      const BsdfSample r = dielectric_sample_local(lobe, u, 0.0f);
      const BsdfSample t = dielectric_sample_local(lobe, u, 1.0f);
      const Vec3 m = ggx_sample_visible_normal(alpha, lobe.wo, u);
      const float f = fresnel_dielectric(glm::dot(lobe.wo, m), eta);
      sum += double(f) * r.weight.x + (f < 1.0f ? double(1.0f - f) * t.weight.x : 0.0);
    }
  }
  return float(sum / (kN * kN));
}

}  // namespace

DielectricAlbedo dielectric_albedo(float alpha, float ior, GgxShadowing shadowing) {
  DielectricAlbedo table;
  for (int i = 0; i <= DielectricAlbedo::kMu; ++i) {
    const float cos_o = std::max(float(i) / DielectricAlbedo::kMu, 1e-3f);
    table.entering[size_t(i)] = albedo_at(alpha, ior, shadowing, cos_o);
    table.leaving[size_t(i)] = albedo_at(alpha, 1.0f / ior, shadowing, cos_o);
  }
  return table;
}

namespace {
// Written once per id before the id is handed out (under the mutex), read without a lock.
std::array<std::atomic<const DielectricAlbedo*>, kMaxDielectricAlbedos> g_tables{};
}  // namespace

int32_t shared_dielectric_albedo(float alpha, float ior, GgxShadowing shadowing) {
  static std::mutex mutex;
  static auto* ids = new std::map<std::tuple<float, float, int>, int32_t>();  // never freed, as the tables
  const std::lock_guard<std::mutex> lock(mutex);
  const auto key = std::make_tuple(alpha, ior, int(shadowing));
  if (auto it = ids->find(key); it != ids->end()) return it->second;
  const int32_t id = int32_t(ids->size());
  if (id >= kMaxDielectricAlbedos) return -1;
  g_tables[size_t(id)].store(new DielectricAlbedo(dielectric_albedo(alpha, ior, shadowing)), std::memory_order_release);
  (*ids)[key] = id;
  return id;
}

const DielectricAlbedo& dielectric_albedo_table(int32_t id) {
  return *g_tables[size_t(id)].load(std::memory_order_acquire);
}

float multiscatter_glass_scale(const DielectricAlbedo& table, bool entering, float cos_o) {
  const auto& e = entering ? table.entering : table.leaving;
  const float x = std::clamp(cos_o, 0.0f, 1.0f) * DielectricAlbedo::kMu;
  const int i = std::min(int(x), DielectricAlbedo::kMu - 1);
  const float t = x - float(i);
  const float albedo = (1.0f - t) * e[size_t(i)] + t * e[size_t(i) + 1];
  return albedo > 0.05f ? 1.0f / albedo : 20.0f;  // E is far above 0.05 for alpha <= 1
}

}  // namespace toyrt
