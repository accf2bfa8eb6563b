// Blender 3.x's Principled diffuse: Burley's diffuse of the Disney BRDF (2012), as Cycles 3.x
// evaluates it (its "principled diffuse" closure with every component), a Lambert albedo / pi
// times a factor that depends on both directions:
//     (1 - FL / 2) (1 - FV / 2)  +  R (FL + FV + FL FV (R - 1)),   R = roughness (1 + wi.wo)
// with FL = (1 - cos_i)^5 and FV = (1 - cos_o)^5 (Schlick's weights, each cosine clamped to
// [0, 1]). The first term darkens the surface towards grazing on either side; the second is the
// retro-reflection of rough surfaces, which brightens grazing views lit from behind the viewer
// (R is roughness x 2 cos^2 of the half-angle between wi and wo: 2 (wi.h)^2 = 1 + wi.wo).
// Roughness 0 and normal incidence on both sides give exactly Lambert (factor 1).
//
// The factor is symmetric in wi and wo (reciprocal), and it is what the integrator multiplies a
// diffuse point's constant f by, per light direction, when a material hands it one
// (Scatter::burley): the direction is sampled as Lambert's (cosine), as Cycles 3.x samples it.
// A normal-mapped diffuse point (any material) rides the same path with Cycles' bump shadowing
// term (materials/bump_shadowing.h) as a further factor, Burley's terms on or off.
#pragma once

#include "core/math.h"
#include "materials/bump_shadowing.h"

#include <algorithm>

namespace toyrt {

struct BurleyDiffuse {
  Vec3 n{0.0f, 0.0f, 1.0f};  // the shading normal on wo's side (the integrator's ns)
  Vec3 wo{0.0f, 0.0f, 1.0f};
  float roughness = 0.0f;  // the Principled Roughness, [0, 1]
  bool burley = true;      // false: Lambert, only the bump term below
  BumpShadowing bump = BumpShadowing::None;
  Vec3 smooth{0.0f, 0.0f, 1.0f};  // the normal before the normal map, on n's side (for `bump`)
};

// Schlick's weight (1 - c)^5, c clamped to [0, 1] (a cosine below 0 counts as grazing).
inline float schlick_weight(float c) {
  const float m = std::clamp(1.0f - c, 0.0f, 1.0f);
  const float m2 = m * m;
  return m2 * m2 * m;
}

// The factor on albedo / pi for light arriving along wi (world, unit; the caller checks wi is
// above the shading normal).
inline float burley_factor(const BurleyDiffuse& b, const Vec3& wi) {
  float factor = 1.0f;
  if (b.burley) {
    const float fl = schlick_weight(glm::dot(b.n, wi));
    const float fv = schlick_weight(glm::dot(b.n, b.wo));
    const float lambert = (1.0f - 0.5f * fl) * (1.0f - 0.5f * fv);
    const float r = b.roughness * (1.0f + glm::dot(wi, b.wo));
    factor = lambert + r * (fl + fv + fl * fv * (r - 1.0f));
  }
  if (b.bump != BumpShadowing::None) factor *= bump_shadowing(b.bump, b.smooth, b.n, wi);
  return factor;
}

}  // namespace toyrt
