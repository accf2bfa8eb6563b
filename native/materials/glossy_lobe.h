// A glossy (microfacet GGX) reflection lobe as a material hands it to the integrator, which then
// needs three things of it without knowing the material: its value and pdf for a light's
// direction (next-event estimation, MIS), and a sampled direction to continue the path along.
// Plain data: the shading frame, wo in it, the tint and alpha, and the Fresnel term: none (the
// tint alone, Blender's Glossy BSDF), Principled's dielectric blend, or 4.0+'s metal F82-tint
// (materials/principled.h).
#pragma once

#include "core/math.h"
#include "materials/clearcoat.h"
#include "materials/fresnel.h"
#include "sampling/beckmann.h"
#include "sampling/frame.h"
#include "sampling/ggx.h"

#include <algorithm>
#include <cstdint>

namespace toyrt {

enum class LobeFresnel : uint8_t {
  None,        // the tint alone
  Dielectric,  // mix(f0, 1, s), s the curve of `ior` remapped to [0, 1]: (F_ior - F0(ior)) / (1 - F0(ior))
  F82Tint,     // Schlick's mix(f0, 1, (1 - c)^5) less f82_b c (1 - c)^6 (Blender 4.0+'s metals)
};

struct GlossyLobe {
  Frame frame{Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};  // z: the shading normal on wo's side
  Vec3 wo{0.0f, 0.0f, 1.0f};                                 // local, unit, wo.z > 0
  Vec3 tint{0.0f};  // the Fresnel term as Blender's Glossy BSDF has it: the colour, at every angle
  float alpha = kGgxMinAlpha;
  GgxShadowing shadowing = GgxShadowing::Separable;
  MicrofacetDistribution distribution = MicrofacetDistribution::Ggx;  // Beckmann: the Glossy BSDF's choice
  // Blender 3.x's Principled Clearcoat: GTR1 with fixed masking, sampled as GGX with Cycles' pdf
  // (materials/clearcoat.h); shadowing is then unread.
  bool clearcoat = false;
  // The Fresnel term on the microfacet normal, times the tint: f0 sets its strength at normal
  // incidence; the dielectric curve's shape comes from ior, the metal's dip towards grazing from
  // f82_b.
  LobeFresnel fresnel = LobeFresnel::None;
  Vec3 f0{1.0f};
  float ior = 1.0f;
  float ior_f0 = 0.0f;  // F0(ior)
  Vec3 f82_b{0.0f};
};

// The Fresnel factor for the microfacet normal between wo and wi (local, unit, both above).
inline Vec3 lobe_fresnel(const GlossyLobe& lobe, const Vec3& wi) {
  if (lobe.fresnel == LobeFresnel::None) return Vec3(1.0f);
  const Vec3 h = glm::normalize(lobe.wo + wi);
  const float c = std::clamp(glm::dot(lobe.wo, h), 0.0f, 1.0f);
  if (lobe.fresnel == LobeFresnel::Dielectric) {
    const float s = std::clamp((fresnel_dielectric(c, lobe.ior) - lobe.ior_f0) / (1.0f - lobe.ior_f0), 0.0f, 1.0f);
    return glm::mix(lobe.f0, Vec3(1.0f), s);
  }
  return fresnel_f82(c, lobe.f0, lobe.f82_b);
}

struct BsdfEval {
  Vec3 f{0.0f};      // BSDF value (1 / sr)
  float pdf = 0.0f;  // solid-angle density with which sample() draws the direction
};

struct BsdfSample {
  Vec3 wi{0.0f};      // world, unit
  Vec3 weight{0.0f};  // f cos / pdf; 0: no continuation
  float pdf = 0.0f;
};

// wi: world, unit. The caller checks that wi leaves on the geometric normal's side.
inline BsdfEval evaluate_lobe(const GlossyLobe& lobe, const Vec3& wi) {
  const Vec3 wi_local = lobe.frame.to_local(wi);
  const GgxEval e = lobe.clearcoat ? clearcoat_eval(lobe.alpha, lobe.wo, wi_local)
                    : lobe.distribution == MicrofacetDistribution::Beckmann
                        ? beckmann_reflection_eval(lobe.alpha, lobe.shadowing, lobe.wo, wi_local)
                        : ggx_reflection_eval(lobe.alpha, lobe.shadowing, lobe.wo, wi_local);
  if (!(e.f > 0.0f)) return {Vec3(0.0f), e.pdf};
  return {lobe.tint * lobe_fresnel(lobe, wi_local) * e.f, e.pdf};
}

inline BsdfSample sample_lobe(const GlossyLobe& lobe, const Vec2& u) {
  const GgxSample s = lobe.clearcoat ? clearcoat_sample(lobe.alpha, lobe.wo, u)
                      : lobe.distribution == MicrofacetDistribution::Beckmann
                          ? beckmann_reflection_sample(lobe.alpha, lobe.shadowing, lobe.wo, u)
                          : ggx_reflection_sample(lobe.alpha, lobe.shadowing, lobe.wo, u);
  if (!(s.weight > 0.0f)) return {lobe.frame.to_world(s.wi), Vec3(0.0f), s.pdf};
  return {lobe.frame.to_world(s.wi), lobe.tint * lobe_fresnel(lobe, s.wi) * s.weight, s.pdf};
}

}  // namespace toyrt
