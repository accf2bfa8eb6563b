// The GGX (Trowbridge-Reitz) microfacet distribution, isotropic, in a local frame whose z axis is
// the macro-surface normal: the normal distribution D, Smith's masking G1 and the two
// masking-shadowing forms Blender has used (separable G1(wo) G1(wi) in 3.x, height-correlated
// 1 / (1 + Lambda(wo) + Lambda(wi)) since 4.0), and sampling by the distribution of visible
// normals (Heitz 2018, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4)), whose pdf
// cancels D so that f cos / pdf is a ratio of masking terms, never above 1.
//
// Roughness follows Cycles: alpha = roughness^2. alpha is kept above kGgxMinAlpha so roughness 0
// is a very sharp lobe (within a few hundredths of a degree of the mirror) rather than a division
// by zero; every formula below is written in sin^2 / cos terms that stay finite at that alpha and
// at grazing angles, where the textbook tan^2 forms produce 0 / 0.
#pragma once

#include "core/math.h"
#include "sampling/warp.h"

#include <algorithm>
#include <cmath>

namespace toyrt {

// alpha^2 = 1e-8: D's peak 1 / (pi alpha^2) ~ 3e7 and the pdfs' squares (MIS) stay in float range.
inline constexpr float kGgxMinAlpha = 1e-4f;

// alpha from Blender's roughness: clamped to [0, 1] as Cycles does; NaN reads as 0 (a mirror).
inline float ggx_alpha(float roughness) {
  const float r = roughness >= 0.0f ? std::min(roughness, 1.0f) : 0.0f;  // false for NaN
  return std::max(r * r, kGgxMinAlpha);
}

// D(m) for a unit microfacet normal m: alpha^2 / (pi (sin^2 + alpha^2 cos^2)^2), 0 below.
inline float ggx_d(float alpha, const Vec3& m) {
  if (m.z <= 0.0f) return 0.0f;
  const float a2 = alpha * alpha;
  const float t = (m.x * m.x + m.y * m.y) + a2 * m.z * m.z;
  return a2 / (kPi * t * t);
}

// Smith's Lambda(w) = (sqrt(1 + alpha^2 tan^2) - 1) / 2, as alpha^2 sin^2 / (2 cos (root + cos))
// to avoid the cancellation near the normal; infinite at the horizon.
inline float ggx_lambda(float alpha, const Vec3& w) {
  if (w.z <= 0.0f) return kInfinity;
  const float s2 = w.x * w.x + w.y * w.y;
  const float a2s2 = alpha * alpha * s2;
  return a2s2 / (2.0f * w.z * (std::sqrt(w.z * w.z + a2s2) + w.z));
}

// G1(w) = 1 / (1 + Lambda) = 2 cos / (cos + sqrt(cos^2 + alpha^2 sin^2)): 0 at the horizon.
inline float ggx_g1(float alpha, const Vec3& w) {
  if (w.z <= 0.0f) return 0.0f;
  const float s2 = w.x * w.x + w.y * w.y;
  return 2.0f * w.z / (w.z + std::sqrt(w.z * w.z + alpha * alpha * s2));
}

// How masking and shadowing combine: Blender 3.x multiplies the two G1 (uncorrelated), 4.0+
// uses the height-correlated form (Heitz 2014), which is never darker.
enum class GgxShadowing { Separable, HeightCorrelated };

inline float ggx_g2(float alpha, GgxShadowing shadowing, const Vec3& wo, const Vec3& wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
  if (shadowing == GgxShadowing::Separable) return ggx_g1(alpha, wo) * ggx_g1(alpha, wi);
  return 1.0f / (1.0f + ggx_lambda(alpha, wo) + ggx_lambda(alpha, wi));
}

// A microfacet normal drawn with density D_wo(m) = G1(wo) max(0, wo . m) D(m) / wo.z (the normals
// wo sees), for wo.z > 0: stretch wo to the alpha = 1 configuration, sample the projected
// hemisphere there (a disk whose far half is squeezed by the view angle), and unstretch.
inline Vec3 ggx_sample_visible_normal(float alpha, const Vec3& wo, const Vec2& u) {
  const Vec3 vh = glm::normalize(Vec3(alpha * wo.x, alpha * wo.y, wo.z));
  const float len2 = vh.x * vh.x + vh.y * vh.y;
  const Vec3 t1 = len2 > 0.0f ? Vec3(-vh.y, vh.x, 0.0f) / std::sqrt(len2) : Vec3(1.0f, 0.0f, 0.0f);
  const Vec3 t2 = glm::cross(vh, t1);
  const float r = std::sqrt(u.x), phi = 2.0f * kPi * u.y;
  const float p1 = r * std::cos(phi);
  const float s = 0.5f * (1.0f + vh.z);
  const float p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * r * std::sin(phi);
  const Vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
  return glm::normalize(Vec3(alpha * nh.x, alpha * nh.y, std::max(nh.z, 0.0f)));
}

// sqrt(cos^2 + alpha^2 sin^2) of a direction: with it G1 = 2 cos / (cos + root), and the
// lobe's terms below divide by (cos + root) or by sums of such roots instead of by cosines, so
// they stay finite down to the horizon.
inline float ggx_root(float alpha, const Vec3& w) {
  return std::sqrt(w.z * w.z + alpha * alpha * (w.x * w.x + w.y * w.y));
}

// Directions closer to the horizon than this carry no energy the lobe can represent in float:
// f and pdf are 0 there (a set of measure zero, so nothing is lost).
inline constexpr float kGgxMinCos = 1e-7f;

// The reflection lobe's value and sampling density for directions wo, wi (local, unit), without
// Fresnel: f = D(h) G2 / (4 cos_o cos_i), and the visible-normal sampler's pdf of wi,
// D_wo(h) / (4 wo . h) = G1(wo) D(h) / (4 cos_o) = D(h) / (2 (cos_o + root_o)). With the roots,
// G2 / (cos_o cos_i) is G1(wo) G1(wi) / (cos_o cos_i) = 4 / ((cos_o + root_o)(cos_i + root_i))
// (separable) or 2 / (cos_i root_o + cos_o root_i) (height-correlated). Both 0 unless wo and wi
// are above the surface.
struct GgxEval {
  float f = 0.0f;
  float pdf = 0.0f;
};
inline GgxEval ggx_reflection_eval(float alpha, GgxShadowing shadowing, const Vec3& wo, const Vec3& wi) {
  if (!(wo.z >= kGgxMinCos && wi.z >= kGgxMinCos)) return {};
  const Vec3 h = glm::normalize(wo + wi);  // wo + wi has z > 0, so a length > 0
  const float d = ggx_d(alpha, h);
  const float ro = ggx_root(alpha, wo), ri = ggx_root(alpha, wi);
  const float g2_over_cos =
      shadowing == GgxShadowing::Separable ? 4.0f / ((wo.z + ro) * (wi.z + ri)) : 2.0f / (wi.z * ro + wo.z * ri);
  return {0.25f * d * g2_over_cos, d / (2.0f * (wo.z + ro))};
}

// A reflected direction from the visible normals, with weight f cos_i / pdf = G2 / G1(wo) (in
// [0, 1]: G1(wi) separable, cos_i (cos_o + root_o) / (cos_i root_o + cos_o root_i) correlated) and
// its pdf; weight and pdf are 0 when the reflection leaves below the surface.
struct GgxSample {
  Vec3 wi{0.0f, 0.0f, 1.0f};
  float weight = 0.0f;
  float pdf = 0.0f;
};
inline GgxSample ggx_reflection_sample(float alpha, GgxShadowing shadowing, const Vec3& wo, const Vec2& u) {
  GgxSample s;
  if (!(wo.z >= kGgxMinCos)) return s;
  const Vec3 m = ggx_sample_visible_normal(alpha, wo, u);
  s.wi = 2.0f * glm::dot(wo, m) * m - wo;
  if (!(s.wi.z >= kGgxMinCos)) return s;
  const float ro = ggx_root(alpha, wo), ri = ggx_root(alpha, s.wi);
  s.weight = shadowing == GgxShadowing::Separable ? 2.0f * s.wi.z / (s.wi.z + ri)
                                                  : s.wi.z * (wo.z + ro) / (s.wi.z * ro + wo.z * ri);
  s.pdf = ggx_d(alpha, m) / (2.0f * (wo.z + ro));
  if (!(s.pdf > 0.0f) || !std::isfinite(s.pdf)) s = GgxSample{s.wi, 0.0f, 0.0f};
  return s;
}

}  // namespace toyrt
