// The Beckmann microfacet distribution, isotropic, in a local frame whose z axis is the
// macro-surface normal: D, Smith's Lambda by Walter et al.'s rational fit (2007, eq. 27; the one
// Cycles evaluates, so that masking matches it), and sampling of D(m) m.z. alpha = roughness^2,
// as for GGX (sampling/ggx.h). And the reflection lobe built of them, the pair ggx.h has for GGX
// (Blender's Glossy BSDF with its Beckmann distribution).
#pragma once

#include "core/math.h"
#include "sampling/ggx.h"  // GgxShadowing, and the GgxEval / GgxSample records the pair shares

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace toyrt {

// D(m) = exp(-tan^2 / alpha^2) / (pi alpha^2 cos^4), 0 below.
inline float beckmann_d(float alpha, const Vec3& m) {
  if (m.z <= 0.0f) return 0.0f;
  const float c2 = m.z * m.z, a2 = alpha * alpha;
  const float tan2 = (m.x * m.x + m.y * m.y) / c2;
  return std::exp(-tan2 / a2) / (kPi * a2 * c2 * c2);
}

// Lambda with a = 1 / (alpha tan): (1 - 1.259 a + 0.396 a^2) / (3.535 a + 2.181 a^2) below
// a = 1.6, 0 above (within 0.35 % of the exact erf form); infinite at the horizon.
inline float beckmann_lambda(float alpha, const Vec3& w) {
  if (w.z <= 0.0f) return kInfinity;
  const float s = std::sqrt(std::max(0.0f, w.x * w.x + w.y * w.y));
  if (!(s > 0.0f)) return 0.0f;
  const float a = w.z / (alpha * s);
  if (a >= 1.6f) return 0.0f;
  return (1.0f - 1.259f * a + 0.396f * a * a) / (3.535f * a + 2.181f * a * a);
}

// A normal with density D(m) m.z: tan^2 = -alpha^2 ln(1 - u.x), phi = 2 pi u.y.
inline Vec3 beckmann_sample_normal(float alpha, const Vec2& u) {
  const float tan2 = -alpha * alpha * std::log(std::max(1.0f - u.x, 1e-30f));
  const float cos_t = 1.0f / std::sqrt(1.0f + tan2), sin_t = std::sqrt(std::max(0.0f, 1.0f - cos_t * cos_t));
  const float phi = 2.0f * kPi * u.y;
  return Vec3(sin_t * std::cos(phi), sin_t * std::sin(phi), cos_t);
}

// Which microfacet distribution a lobe uses (Blender's distribution menus; Ggx also stands for
// Multiscatter GGX, whose compensation the material applies).
enum class MicrofacetDistribution : uint8_t { Ggx, Beckmann };

// Smith's G2 of Walter's Lambda: G1(wo) G1(wi) (separable, Cycles 3.x) or 1 / (1 + Lambda_o +
// Lambda_i) (height-correlated, 4.0+).
inline float beckmann_g2(float alpha, GgxShadowing shadowing, const Vec3& wo, const Vec3& wi) {
  const float lo = beckmann_lambda(alpha, wo), li = beckmann_lambda(alpha, wi);
  return shadowing == GgxShadowing::Separable ? 1.0f / ((1.0f + lo) * (1.0f + li)) : 1.0f / (1.0f + lo + li);
}

// f = D G2 / (4 cos_o cos_i) without the Fresnel term, and the density beckmann_reflection_sample
// draws wi with: normals of density D(m) m.z reflected, D(h) h.z / (4 wo.h). Both 0 unless wo and
// wi are above the surface.
inline GgxEval beckmann_reflection_eval(float alpha, GgxShadowing shadowing, const Vec3& wo, const Vec3& wi) {
  if (!(wo.z >= kGgxMinCos && wi.z >= kGgxMinCos)) return {};
  const Vec3 h = glm::normalize(wo + wi);
  const float d = beckmann_d(alpha, h);
  const float cos_oh = std::max(glm::dot(wo, h), 1e-7f);
  return {d * beckmann_g2(alpha, shadowing, wo, wi) / (4.0f * wo.z * wi.z), d * h.z / (4.0f * cos_oh)};
}

// A reflected direction from a normal of density D(m) m.z (Beckmann's visible normals have no
// closed form; a normal facing away from wo gives no direction), with weight f cos_i / pdf =
// G2 (wo.m) / (cos_o m.z) and its pdf; weight and pdf 0 when there is no reflection above.
inline GgxSample beckmann_reflection_sample(float alpha, GgxShadowing shadowing, const Vec3& wo, const Vec2& u) {
  GgxSample s;
  if (!(wo.z >= kGgxMinCos)) return s;
  const Vec3 m = beckmann_sample_normal(alpha, u);
  const float cos_om = glm::dot(wo, m);
  if (!(cos_om > 0.0f)) return s;
  s.wi = 2.0f * cos_om * m - wo;
  if (!(s.wi.z >= kGgxMinCos)) return s;
  s.weight = beckmann_g2(alpha, shadowing, wo, s.wi) * cos_om / (wo.z * m.z);
  s.pdf = beckmann_d(alpha, m) * m.z / (4.0f * cos_om);
  if (!(s.pdf > 0.0f) || !std::isfinite(s.pdf) || !std::isfinite(s.weight)) s = GgxSample{s.wi, 0.0f, 0.0f};
  return s;
}

}  // namespace toyrt
