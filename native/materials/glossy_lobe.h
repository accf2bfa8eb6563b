// A glossy (microfacet GGX) reflection lobe as a material hands it to the integrator, which then
// needs three things of it without knowing the material: its value and pdf for a light's
// direction (next-event estimation, MIS), and a sampled direction to continue the path along.
// Plain data: the shading frame, wo in it, the tint and alpha; one lobe per Scatter, so a
// future Principled specular layer returns the same struct.
#pragma once

#include "core/math.h"
#include "sampling/frame.h"
#include "sampling/ggx.h"

namespace toyrt {

struct GlossyLobe {
  Frame frame{Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};  // z: the shading normal on wo's side
  Vec3 wo{0.0f, 0.0f, 1.0f};                                 // local, unit, wo.z > 0
  Vec3 tint{0.0f};  // the Fresnel term as Blender's Glossy BSDF has it: the colour, at every angle
  float alpha = kGgxMinAlpha;
  GgxShadowing shadowing = GgxShadowing::Separable;
};

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
  const GgxEval e = ggx_reflection_eval(lobe.alpha, lobe.shadowing, lobe.wo, lobe.frame.to_local(wi));
  return {lobe.tint * e.f, e.pdf};
}

inline BsdfSample sample_lobe(const GlossyLobe& lobe, const Vec2& u) {
  const GgxSample s = ggx_reflection_sample(lobe.alpha, lobe.shadowing, lobe.wo, u);
  return {lobe.frame.to_world(s.wi), lobe.tint * s.weight, s.pdf};
}

}  // namespace toyrt
