#include "materials/dielectric_albedo.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <mutex>
#include <tuple>

#include <tbb/parallel_for.h>

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

// E_avg of each side, trapezoids over the table's points.
void set_averages(DielectricAlbedo& table) {
  for (int side = 0; side < 2; ++side) {
    const auto& e = side == 0 ? table.entering : table.leaving;
    double sum = 0.0;
    for (int i = 0; i < DielectricAlbedo::kMu; ++i) {
      const double mu0 = double(i) / DielectricAlbedo::kMu, mu1 = double(i + 1) / DielectricAlbedo::kMu;
      sum += (double(e[size_t(i)]) * mu0 + double(e[size_t(i) + 1]) * mu1) / DielectricAlbedo::kMu;
    }
    (side == 0 ? table.entering_average : table.leaving_average) = float(sum);
  }
}

}  // namespace

double cycles_table_albedo(float alpha, float eta, float cos_o) {
  constexpr int kN = 128;
  const Vec3 wo(std::sqrt(std::max(0.0f, 1.0f - cos_o * cos_o)), 0.0f, cos_o);
  const double lo = ggx_lambda(alpha, wo);
  double sum = 0.0;
  for (int i = 0; i < kN; ++i) {
    for (int j = 0; j < kN; ++j) {
      const Vec3 m = ggx_sample_visible_normal(alpha, wo, Vec2((float(i) + 0.5f) / kN, (float(j) + 0.5f) / kN));
      const float c = glm::dot(wo, m);
      if (!(c > 0.0f)) continue;
      const double f = fresnel_dielectric(c, eta);
      const Vec3 r = 2.0f * c * m - wo;
      if (r.z > 0.0f) sum += f * (1.0 + lo) / (1.0 + lo + ggx_lambda(alpha, r));
      if (f < 1.0) {  // Snell at m (1 / eta: n_near / n_far); kept whichever side it lands on
        const double ei = 1.0 / eta, cos_t = std::sqrt(std::max(0.0, 1.0 - ei * ei * (1.0 - double(c) * c)));
        const Vec3 t = glm::normalize(-float(ei) * wo + float(ei * c - cos_t) * m);
        // A refraction that comes back to wo's side is shadowed as if it were there: Lambda at |t.z|.
        if (t.z != 0.0f) sum += (1.0 - f) * (1.0 + lo) / (1.0 + lo + ggx_lambda(alpha, Vec3(t.x, t.y, std::abs(t.z))));
      }
    }
  }
  return sum / (double(kN) * kN);
}

DielectricAlbedo dielectric_albedo(float alpha, float ior, GgxShadowing shadowing) {
  DielectricAlbedo table;
  if (shadowing == GgxShadowing::Separable) {  // no Cycles table to follow: the lobe's own albedo
    for (int i = 0; i <= DielectricAlbedo::kMu; ++i) {
      const float cos_o = std::max(float(i) / DielectricAlbedo::kMu, 1e-3f);
      table.entering[size_t(i)] = albedo_at(alpha, ior, shadowing, cos_o);
      table.leaving[size_t(i)] = albedo_at(alpha, 1.0f / ior, shadowing, cos_o);
    }
    set_averages(table);
    return table;
  }
  // Cycles' grid: rough = sqrt(alpha) at x / 15, z at k / 15 (z^4 = F0 of the IOR >= 1, clamped
  // to [1e-4, 0.99]), cos_o at i / 15; the material's E is the bilinear mix of its four (rough,
  // z) corners, point by point in cos_o, as a trilinear read of that grid gives it.
  const float n = ior < 1.0f ? 1.0f / ior : ior;
  const float xr = std::clamp(std::sqrt(alpha), 0.0f, 1.0f) * 15.0f;
  const float xz = std::clamp(std::sqrt(std::abs((n - 1.0f) / (n + 1.0f))), 0.0f, 1.0f) * 15.0f;
  const int r0 = std::min(int(xr), 15), z0 = std::min(int(xz), 15);
  const int r1 = std::min(r0 + 1, 15), z1 = std::min(z0 + 1, 15);
  const float tr = xr - float(r0), tz = xz - float(z0);
  const auto corner_alpha = [](int x) {
    const float rough = std::clamp(float(x) / 15.0f, 1e-4f, 1.0f);
    return rough * rough;
  };
  const auto corner_ior = [](int k) {
    const float z = std::clamp(float(k) / 15.0f, 1e-4f, 0.99f);
    return (1.0f + z * z) / (1.0f - z * z);  // sqrt(F0) = z^2
  };
  // 2 sides x 16 cosines, each up to four corner estimates (those of weight 0 skipped): in
  // parallel, each task writing its own entry, so the table does not depend on the scheduling.
  tbb::parallel_for(0, 2 * (DielectricAlbedo::kMu + 1), [&](int task) {
    const int side = task / (DielectricAlbedo::kMu + 1), i = task % (DielectricAlbedo::kMu + 1);
    const bool inverted = (side == 0) != (ior >= 1.0f);  // eta < 1: the inverse table
    const float cos_o = std::max(float(i) / DielectricAlbedo::kMu, 1e-4f);
    double e = 0.0;
    for (int a = 0; a < 2; ++a) {
      for (int b = 0; b < 2; ++b) {
        const double w = (a ? tr : 1.0 - tr) * (b ? tz : 1.0 - tz);
        if (w == 0.0) continue;
        const float g = corner_ior(b ? z1 : z0);
        const double v = cycles_table_albedo(corner_alpha(a ? r1 : r0), inverted ? 1.0f / g : g, cos_o);
        e += w * std::clamp(v, 0.0, 1.0);  // the tables are saturated
      }
    }
    (side == 0 ? table.entering : table.leaving)[size_t(i)] = float(e);
  });
  set_averages(table);
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

Vec3 multiscatter_glass_factor(const DielectricAlbedo& table, bool entering, float cos_o, const Vec3& fss) {
  const float scale = multiscatter_glass_scale(table, entering, cos_o);
  if (fss == Vec3(1.0f)) return Vec3(scale);
  const float avg = entering ? table.entering_average : table.leaving_average;
  const Vec3 f_ms = fss * avg / (Vec3(1.0f) - fss * (1.0f - avg));
  return Vec3(1.0f) + f_ms * (scale - 1.0f);  // (1 - E) / E = 1 / E - 1
}

}  // namespace toyrt
