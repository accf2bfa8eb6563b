// A rough dielectric interface as a microfacet lobe (Walter et al. 2007, "Microfacet Models for
// Refraction through Rough Surfaces"), GGX normals (sampling/ggx.h), on both sides of the surface:
// wi in wo's hemisphere is a reflection, wi in the other one a transmission. The integrator needs
// of it what it needs of a glossy lobe (a value and pdf for a light's direction, a sampled
// direction), on both sides: render/dielectric_lighting.h.
//
// Sampling: GGX's visible normals (weights never above 1), Beckmann's D cos (normals facing away from
// wo are drawn and lost; Cycles 3.4's Glass and Refraction default to Beckmann).
//
// Local frame: z is the shading normal on wo's side, wo.z > 0. eta = n_far / n_near, the index
// on the side wi transmits into over wo's (ior entering, 1 / ior leaving). With h the half vector
// (wo + wi for a reflection, the generalised wo + eta wi, turned to z > 0, for a transmission):
//     reflection    f = W_r(h) D G2 / (4 cos_o cos_i)
//     transmission  f = W_t(h) D G2 eta^2 |wi.h| |wo.h| / (cos_o |cos_i| (wo.h + eta wi.h)^2)
// The transmission carries eta^2 where Walter's radiance BTDF has none: that is the form Cycles
// uses, with no 1 / eta^2 radiance scaling (refraction.h), so that the sampler's weight
// f |cos_i| / pdf is the same masking ratio G2 / G1(wo) as a reflection's, never above 1, and
// roughness -> 0 gives the specular materials' answers.
//
// W_r, W_t (the weights, also the probabilities with which the sampler picks either side):
//   Refraction  0 and 1 (Blender's Refraction BSDF: transmission only, no Fresnel term)
//   Glass       F(wo.h) and 1 - F(wo.h), the Fresnel term on the microfacet (Cycles 4.0+)
//   Glass3x     F(cos_o) and 1 - F(cos_o), the Fresnel term of the shading normal weighting two
//               lobes without one (Cycles 3.x's Glass BSDF closures). As two closures, each side
//               may have its own roughness (3.x Principled's Transmission Roughness): the
//               transmission's alpha is `alpha_transmit` when that is set.
// A microfacet normal that cannot refract (total internal reflection) gives no transmission: for
// Glass its F is 1 and the sampler reflects; Refraction and Glass3x lose that energy, as Cycles.
//
// Pairs no microfacet connects: a wi across the surface whose generalised half vector faces away
// from wo or from wi is no refraction, and the sampler never makes it. Cycles evaluates such a pair
// all the same (3.4's GGX transmission and 4.0+'s bsdf_microfacet_eval take |wo.h| and |wi.h|
// without checking the configuration), so its light samples through a rough glass receive light
// there and its MIS weighs them by that pdf. On one GGX interface at roughness 0.7 between the
// camera and a lamp, that is 5.2 % of the light through it in 3.4 (4.2-4.7 % in 5.0).
// `unchecked_refraction` (set by the materials) evaluates them as Cycles does: the same formulas
// with |wo.h|, |wi.h| and the Fresnel term at |wo.h|. The sampler is unchanged, so the lobe is not
// normalised against it there: dielectric_refracts() tells the regions apart (the tests' pdf
// masses leave these pairs out).
#pragma once

#include "core/math.h"
#include "materials/fresnel.h"
#include "materials/glossy_lobe.h"
#include "sampling/beckmann.h"
#include "sampling/frame.h"
#include "sampling/ggx.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace toyrt {

enum class DielectricKind : uint8_t { Refraction, Glass, Glass3x };

struct DielectricLobe {
  Frame frame{Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};  // z: the shading normal on wo's side
  Vec3 wo{0.0f, 0.0f, 1.0f};                                 // local, unit, wo.z > 0
  // The colours of the two sides (Blender's Glass BSDF Color on both, Principled's Specular Tint
  // and base colour on each), times 4.0+'s multiscatter energy scale.
  Vec3 tint{1.0f};           // reflection
  Vec3 transmit_tint{1.0f};  // transmission
  float alpha = 0.1f;
  // Glass3x only: the transmission's own alpha (0: alpha). The other kinds choose the side by the
  // Fresnel term of the sampled microfacet, so both sides must share one distribution.
  float alpha_transmit = 0.0f;
  MicrofacetDistribution distribution = MicrofacetDistribution::Ggx;
  float eta = 1.45f;  // n_far / n_near, != 1
  GgxShadowing shadowing = GgxShadowing::Separable;
  DielectricKind kind = DielectricKind::Glass;
  float fresnel_macro = 0.0f;         // Glass3x: F(cos_o)
  bool unchecked_refraction = false;  // evaluate pairs no microfacet refracts, as Cycles (above)
};

namespace dielectric_detail {

inline float transmission_alpha(const DielectricLobe& lobe) {
  return lobe.alpha_transmit > 0.0f ? lobe.alpha_transmit : lobe.alpha;
}

// The reflection weight W_r for microfacet normal h (W_t = 1 - W_r).
inline float reflect_weight(const DielectricLobe& lobe, float cos_oh) {
  if (lobe.kind == DielectricKind::Refraction) return 0.0f;
  if (lobe.kind == DielectricKind::Glass3x) return lobe.fresnel_macro;
  return fresnel_dielectric(cos_oh, lobe.eta);
}

// The helpers below take the side's alpha: lobe.alpha, or transmission_alpha(lobe).
inline float normal_density(const DielectricLobe& lobe, float alpha, const Vec3& m) {
  return lobe.distribution == MicrofacetDistribution::Ggx ? ggx_d(alpha, m) : beckmann_d(alpha, m);
}

// G2 / (cos_o |cos_i|), wi_up: wi turned to wo's side. GGX through the roots of ggx.h (finite
// down to the horizon).
inline float g2_over_cos(const DielectricLobe& lobe, float alpha, const Vec3& wi_up) {
  const Vec3& wo = lobe.wo;
  if (lobe.distribution == MicrofacetDistribution::Beckmann) {
    const float lo = beckmann_lambda(alpha, wo), li = beckmann_lambda(alpha, wi_up);
    const float g2 =
        lobe.shadowing == GgxShadowing::Separable ? 1.0f / ((1.0f + lo) * (1.0f + li)) : 1.0f / (1.0f + lo + li);
    return g2 / (wo.z * wi_up.z);
  }
  const float ro = ggx_root(alpha, wo), ri = ggx_root(alpha, wi_up);
  return lobe.shadowing == GgxShadowing::Separable ? 4.0f / ((wo.z + ro) * (wi_up.z + ri))
                                                   : 2.0f / (wi_up.z * ro + wo.z * ri);
}

// The density of the sampled microfacet normal h: GGX's visible normals, G1(wo) (wo.h) D(h) /
// cos_o = 2 (wo.h) D / (cos_o + root_o); Beckmann's D(h) h.z (its visible normals have no closed
// form; normals facing away from wo are drawn and give no sample).
inline float normal_pdf(const DielectricLobe& lobe, float alpha, const Vec3& h, float cos_oh) {
  if (lobe.distribution == MicrofacetDistribution::Beckmann) return beckmann_d(alpha, h) * h.z;
  return 2.0f * cos_oh * ggx_d(alpha, h) / (lobe.wo.z + ggx_root(alpha, lobe.wo));
}

// The sampler's weight f |cos_i| / pdf = D G2 (wo.m) / (cos_o pdf_m): for GGX G2 / G1(wo), in
// [0, 1] (as ggx_reflection_sample's); for Beckmann G2 (wo.m) / (cos_o m.z).
inline float sample_weight(const DielectricLobe& lobe, float alpha, const Vec3& m, float cos_om, const Vec3& wi_up) {
  const Vec3& wo = lobe.wo;
  if (lobe.distribution == MicrofacetDistribution::Beckmann)
    return g2_over_cos(lobe, alpha, wi_up) * wi_up.z * cos_om / m.z;
  const float ro = ggx_root(alpha, wo), ri = ggx_root(alpha, wi_up);
  return lobe.shadowing == GgxShadowing::Separable ? 2.0f * wi_up.z / (wi_up.z + ri)
                                                   : wi_up.z * (wo.z + ro) / (wi_up.z * ro + wo.z * ri);
}

inline Vec3 sample_normal(const DielectricLobe& lobe, float alpha, const Vec2& u) {
  return lobe.distribution == MicrofacetDistribution::Ggx ? ggx_sample_visible_normal(alpha, lobe.wo, u)
                                                          : beckmann_sample_normal(alpha, u);
}

}  // namespace dielectric_detail

// wi: local, unit, either side. 0 for directions within kGgxMinCos of the horizon.
inline BsdfEval dielectric_eval_local(const DielectricLobe& lobe, const Vec3& wi) {
  using namespace dielectric_detail;
  const Vec3& wo = lobe.wo;
  if (!(wo.z >= kGgxMinCos) || !(std::abs(wi.z) >= kGgxMinCos)) return {};
  if (wi.z > 0.0f) {
    const Vec3 h = glm::normalize(wo + wi);
    const float cos_oh = glm::dot(wo, h);
    const float w = reflect_weight(lobe, cos_oh);
    if (!(w > 0.0f)) return {};
    const float f = 0.25f * normal_density(lobe, lobe.alpha, h) * g2_over_cos(lobe, lobe.alpha, wi);
    const float pdf = normal_pdf(lobe, lobe.alpha, h, cos_oh) / (4.0f * cos_oh);
    if (!std::isfinite(f) || !std::isfinite(pdf)) return {};
    return {lobe.tint * (w * f), w * pdf};
  }
  Vec3 h = wo + lobe.eta * wi;
  const float len2 = glm::dot(h, h);
  if (!(len2 > 0.0f)) return {};
  h /= std::sqrt(len2);
  if (h.z < 0.0f) h = -h;
  float cos_oh = glm::dot(wo, h), cos_ih = glm::dot(wi, h);
  // ((wo + eta wi).h)^2 = |wo + eta wi|^2; as the product for a refraction (the sampler's form).
  float denom2 = len2;
  if (cos_oh > 0.0f && cos_ih < 0.0f) {
    denom2 = (cos_oh + lobe.eta * cos_ih) * (cos_oh + lobe.eta * cos_ih);
  } else {  // a microfacet facing away from either: no refraction
    if (!lobe.unchecked_refraction) return {};
    cos_oh = std::abs(cos_oh);
    cos_ih = -std::abs(cos_ih);
  }
  const float w = 1.0f - reflect_weight(lobe, cos_oh);
  if (!(w > 0.0f)) return {};
  const float jacobian = lobe.eta * lobe.eta * -cos_ih / denom2;  // d omega_h / d omega_i
  const float alpha = transmission_alpha(lobe);
  const float d = normal_density(lobe, alpha, h);
  const Vec3 wi_up(wi.x, wi.y, -wi.z);
  const float f = d * g2_over_cos(lobe, alpha, wi_up) * cos_oh * jacobian;
  const float pdf = normal_pdf(lobe, alpha, h, cos_oh) * jacobian;
  if (!std::isfinite(f) || !std::isfinite(pdf)) return {};
  return {lobe.transmit_tint * (w * f), w * pdf};
}

// Whether a microfacet refracts wo into wi (local, below the surface): the generalised half
// vector faces both. The sampler's transmissions all are; unchecked_refraction evaluates the rest.
inline bool dielectric_refracts(const DielectricLobe& lobe, const Vec3& wi) {
  Vec3 h = lobe.wo + lobe.eta * wi;
  if (h.z < 0.0f) h = -h;
  return wi.z < 0.0f && glm::dot(lobe.wo, h) > 0.0f && glm::dot(wi, h) < 0.0f;
}

inline BsdfEval dielectric_eval(const DielectricLobe& lobe, const Vec3& wi) {
  return dielectric_eval_local(lobe, lobe.frame.to_local(wi));
}

// u: the visible normal; u_side: reflection or transmission. A weight of 0: no continuation (a
// direction below the horizon of its side, or a transmission through a microfacet under total
// internal reflection for Refraction and Glass3x). wi is local here.
inline BsdfSample dielectric_sample_local(const DielectricLobe& lobe, const Vec2& u, float u_side) {
  using namespace dielectric_detail;
  const Vec3& wo = lobe.wo;
  BsdfSample s;
  if (!(wo.z >= kGgxMinCos)) return s;
  // Glass3x's side does not depend on the microfacet (the shading normal's Fresnel term), so it is
  // known before the normal is drawn, from that side's distribution. The other kinds share one.
  const bool transmit_side = lobe.kind == DielectricKind::Glass3x && !(u_side < lobe.fresnel_macro);
  const float alpha = transmit_side ? transmission_alpha(lobe) : lobe.alpha;
  const Vec3 m = sample_normal(lobe, alpha, u);
  const float cos_om = glm::dot(wo, m);
  if (!(cos_om > 0.0f)) return s;
  const float pr = reflect_weight(lobe, cos_om);
  const float hpdf = normal_pdf(lobe, alpha, m, cos_om);
  if (u_side < pr) {
    s.wi = 2.0f * cos_om * m - wo;
    if (!(s.wi.z >= kGgxMinCos)) return s;
    s.pdf = pr * hpdf / (4.0f * cos_om);
    s.weight = lobe.tint * sample_weight(lobe, alpha, m, cos_om, s.wi);
  } else {
    // Snell at the microfacet: refract() takes n_near / n_far.
    const float eta_i = 1.0f / lobe.eta;
    const float sin2_t = eta_i * eta_i * std::max(0.0f, 1.0f - cos_om * cos_om);
    if (sin2_t >= 1.0f) return s;
    const float cos_t = std::sqrt(1.0f - sin2_t);
    s.wi = glm::normalize(-eta_i * wo + (eta_i * cos_om - cos_t) * m);
    if (!(s.wi.z <= -kGgxMinCos)) return s;
    const float cos_im = glm::dot(s.wi, m);
    const float denom = cos_om + lobe.eta * cos_im;
    s.pdf = (1.0f - pr) * hpdf * lobe.eta * lobe.eta * -cos_im / (denom * denom);
    s.weight = lobe.transmit_tint * sample_weight(lobe, alpha, m, cos_om, Vec3(s.wi.x, s.wi.y, -s.wi.z));
  }
  if (!(s.pdf > 0.0f) || !std::isfinite(s.pdf) || !is_finite(s.weight)) s = BsdfSample{s.wi, Vec3(0.0f), 0.0f};
  return s;
}

inline BsdfSample dielectric_sample(const DielectricLobe& lobe, const Vec2& u, float u_side) {
  BsdfSample s = dielectric_sample_local(lobe, u, u_side);
  s.wi = lobe.frame.to_world(s.wi);
  return s;
}

}  // namespace toyrt
