#include "sampling/ggx_albedo.h"

#include "materials/fresnel.h"
#include "sampling/ggx.h"

#include <algorithm>
#include <cmath>

namespace toyrt {
namespace {

#include "sampling/ggx_albedo_tables.inc"

static_assert(sizeof(kGgxE) / sizeof(float) == kGgxAlbedoSize * kGgxAlbedoSize);
static_assert(sizeof(kGgxEAvg) / sizeof(float) == kGgxAlbedoSize);
static_assert(sizeof(kGgxS) / sizeof(float) == kGgxFresnelBlendSize * kGgxFresnelBlendSize * kGgxFresnelBlendSize);

// Where x in [0, 1] falls on an axis of n entries: the lower entry and the weight of the next.
struct AxisPoint {
  int i0, i1;
  float t;
};
AxisPoint on_axis(float x, int n) {
  x = (x >= 0.0f ? std::min(x, 1.0f) : 0.0f) * float(n - 1);  // NaN reads as 0
  const int i0 = std::min(int(x), n - 1);
  return {i0, std::min(i0 + 1, n - 1), x - float(i0)};
}

float lerp(float a, float b, float t) { return a + t * (b - a); }

// z = sqrt((ior - 1) / (ior + 1)): the fourth root of F0, Cycles' axis for the index.
float ior_axis(float ior) {
  if (!(ior >= 1.0f)) ior = ior > 0.0f ? 1.0f / ior : 1.0f;
  return std::sqrt((ior - 1.0f) / (ior + 1.0f));
}

// The local outgoing direction at cosine mu (in the xz plane; the lobe is isotropic).
Vec3 outgoing(float mu) { return Vec3(std::sqrt(std::max(0.0f, 1.0f - mu * mu)), 0.0f, mu); }

// The mean of g(u) over an n x n grid of cell centres.
template <class G>
double stratified_mean(int n, G&& g) {
  double sum = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) sum += g(Vec2((float(i) + 0.5f) / float(n), (float(j) + 0.5f) / float(n)));
  return sum / (double(n) * double(n));
}

}  // namespace

float lookup_2d(const float* table, int n, float rough, float mu) {
  const AxisPoint x = on_axis(rough, n), y = on_axis(mu, n);
  const float lo = lerp(table[y.i0 * n + x.i0], table[y.i0 * n + x.i1], x.t);
  const float hi = lerp(table[y.i1 * n + x.i0], table[y.i1 * n + x.i1], x.t);
  return lerp(lo, hi, y.t);
}

float ggx_albedo(float roughness, float cos_o) { return lookup_2d(kGgxE, kGgxAlbedoSize, roughness, cos_o); }

float ggx_average_albedo(float roughness) {
  const AxisPoint x = on_axis(roughness, kGgxAlbedoSize);
  return lerp(kGgxEAvg[x.i0], kGgxEAvg[x.i1], x.t);
}

float ggx_fresnel_blend(float roughness, float cos_o, float ior) {
  constexpr int n = kGgxFresnelBlendSize;
  const AxisPoint z = on_axis(ior_axis(ior), n);
  const float lo = lookup_2d(kGgxS + z.i0 * n * n, n, roughness, cos_o);
  const float hi = lookup_2d(kGgxS + z.i1 * n * n, n, roughness, cos_o);
  return lerp(lo, hi, z.t);
}

float ggx_table_roughness(int i, int n) { return std::clamp(float(i) / float(n - 1), 1e-4f, 1.0f); }
float ggx_table_cos(int i, int n) { return std::clamp(float(i) / float(n - 1), 1e-4f, 1.0f); }
float ggx_table_ior(int i, int n) {
  const float z = std::clamp(float(i) / float(n - 1), 1e-4f, 0.99f);
  return ior_from_f0(z * z * z * z);
}

double estimate_ggx_albedo(float roughness, float cos_o, int n) {
  const float alpha = ggx_alpha(roughness);
  const Vec3 wo = outgoing(cos_o);
  return stratified_mean(n, [&](const Vec2& u) {
    return double(ggx_reflection_sample(alpha, GgxShadowing::HeightCorrelated, wo, u).weight);
  });
}

double estimate_ggx_average_albedo(float roughness, int n) {
  double sum = 0.0;
  for (int k = 0; k < n; ++k) {
    const float mu = (float(k) + 0.5f) / float(n);
    sum += 2.0 * mu * estimate_ggx_albedo(roughness, mu, n);
  }
  return sum / n;
}

double estimate_ggx_fresnel_blend(float roughness, float cos_o, float ior, int n) {
  const float alpha = ggx_alpha(roughness);
  const Vec3 wo = outgoing(cos_o);
  const float f0 = f0_from_ior(ior);
  return stratified_mean(n, [&](const Vec2& u) {
    // A reflection that leaves below the surface carries nothing (and counts as 0, as in Cycles'
    // precomputation, so s is the blend of the light actually reflected).
    const Vec3 m = ggx_sample_visible_normal(alpha, wo, u);
    const float c = glm::dot(wo, m);
    const Vec3 wi = 2.0f * c * m - wo;
    if (!(wi.z >= kGgxMinCos)) return 0.0;
    return double(std::clamp((fresnel_dielectric(c, ior) - f0) / (1.0f - f0), 0.0f, 1.0f));
  });
}

}  // namespace toyrt
