// Blender 3.x's Principled Clearcoat as Cycles 3.x evaluates and samples it (read in Cycles 3.4's
// kernel/closure/bsdf_microfacet.h and kernel/svm/closure.h for the facts):
//   - Burley's GTR1 distribution D(h) = (a2 - 1) / (pi ln(a2) (1 + (a2 - 1) cos^2 h)), a2 = alpha^2,
//     alpha = Clearcoat Roughness^2 (the lobe's usual remap), 1 / pi from alpha 1 on;
//   - Smith masking and shadowing of a fixed GGX alpha 0.25, separable, whatever the roughness;
//   - sampled as a GGX lobe of alpha is (its visible normals), but with the pdf G1(wo) D_GTR1(h) /
//     (4 cos_o) reported for it, not the density the sampler has: a sample then weighs G1(wi)
//     times the Fresnel term, and MIS weighs it by that pdf. Matching Cycles 3.4 means this pair,
//     not a consistent GTR1 sampler: the BSDF-sampled half converges to a GGX-shaped reflection,
//     the light-sampled half to the GTR1 lobe, as in Cycles.
// Its Fresnel term (the 0.04 blend of IOR 1.5, i.e. that IOR's curve) and the 0.25 x Clearcoat
// scale are the caller's tint and Fresnel (materials/glossy_lobe.h, materials/principled.cpp).
#pragma once

#include "core/math.h"
#include "sampling/ggx.h"

#include <cmath>

namespace toyrt {

inline constexpr float kClearcoatMaskingAlpha = 0.25f;
inline constexpr float kClearcoatIor = 1.5f;
inline constexpr float kClearcoatF0 = 0.04f;  // F0 of IOR 1.5

// D(m) for a unit microfacet normal m (local, z up): 1 + (a2 - 1) cos^2 written sin^2 + a2 cos^2,
// which stays positive in float next to the normal however small alpha is.
inline float gtr1_d(float alpha, const Vec3& m) {
  if (m.z <= 0.0f) return 0.0f;
  if (alpha >= 1.0f) return kInvPi;
  const float a2 = alpha * alpha;
  const float t = (m.x * m.x + m.y * m.y) + a2 * m.z * m.z;
  return (a2 - 1.0f) / (kPi * std::log(a2) * t);
}

// f without the Fresnel term, D G1(wo) G1(wi) / (4 cos_o cos_i), and Cycles' pdf, as ggx.h's pair.
inline GgxEval clearcoat_eval(float alpha, const Vec3& wo, const Vec3& wi) {
  if (!(wo.z >= kGgxMinCos && wi.z >= kGgxMinCos)) return {};
  const Vec3 h = glm::normalize(wo + wi);
  const float d = gtr1_d(alpha, h);
  const float g1o = ggx_g1(kClearcoatMaskingAlpha, wo), g1i = ggx_g1(kClearcoatMaskingAlpha, wi);
  return {d * g1o * g1i / (4.0f * wo.z * wi.z), g1o * d / (4.0f * wo.z)};
}

// A direction from GGX's visible normals of alpha, its weight G1(wi) (f cos / Cycles' pdf,
// without the Fresnel term) and Cycles' pdf.
inline GgxSample clearcoat_sample(float alpha, const Vec3& wo, const Vec2& u) {
  GgxSample s;
  if (!(wo.z >= kGgxMinCos)) return s;
  const Vec3 m = ggx_sample_visible_normal(alpha, wo, u);
  s.wi = 2.0f * glm::dot(wo, m) * m - wo;
  if (!(s.wi.z >= kGgxMinCos)) return s;
  s.weight = ggx_g1(kClearcoatMaskingAlpha, s.wi);
  s.pdf = ggx_g1(kClearcoatMaskingAlpha, wo) * gtr1_d(alpha, m) / (4.0f * wo.z);
  if (!(s.pdf > 0.0f) || !std::isfinite(s.pdf)) s = GgxSample{s.wi, 0.0f, 0.0f};
  return s;
}

}  // namespace toyrt
