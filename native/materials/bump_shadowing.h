// Cycles' shadowing term for a diffuse closure whose normal a normal map bent: a factor on the
// BRDF per light direction that darkens the bumps' faces turned from the smooth surface's light,
// so bent normals do not light the far side of the terminator (the integrator applies it where a
// material has a normal map: render/normal_mapping.h). Two models, per Blender version (read in
// Cycles' kernels of 3.4 and 5.0):
// - Chiang, Li and Burley, "Taming the Shadow Terminator" (2019), Cycles 3.x: with the smooth
//   normal Ns (flipped to the side of the bent N as seen by wi) g = (Ns.wi) / ((N.wi)(Ns.N)), the
//   factor 1 for g >= 1, 0 for g < 0, else -g^3 + g^2 + g.
// - Conty Estevez, Lecocq and Stein, "A Microfacet-Based Shadowing Function to Solve the Bump
//   Terminator Problem" (2019), Cycles 4.x+ (material "Bump Map Correction", on by default): 0
//   when wi is above one of Ns and N and below the other, else GGX's masking G1 at cos_i = |Ns.wi|
//   with alpha^2 = clamp(tan^2(angle(Ns, N)) / 8, 0, 1).
#pragma once

#include "core/math.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace toyrt {

enum class BumpShadowing : uint8_t { None, Chiang, Conty };

// The factor for light along wi (unit), smooth and bent unit normals on the same side.
inline float bump_shadowing(BumpShadowing kind, const Vec3& smooth, const Vec3& bent, const Vec3& wi) {
  if (kind == BumpShadowing::None || smooth == bent) return 1.0f;
  const float cos_bent_i = glm::dot(bent, wi), cos_smooth_i = glm::dot(smooth, wi), cos_d = glm::dot(smooth, bent);
  if (kind == BumpShadowing::Chiang) {
    const float den = cos_bent_i * cos_d;  // Ns flipped to N's side as wi sees it: the signs cancel
    const float g = den != 0.0f ? cos_smooth_i / den : 0.0f;
    if (g >= 1.0f) return 1.0f;
    if (!(g >= 0.0f)) return 0.0f;
    return g * (1.0f + g - g * g);
  }
  if (cos_smooth_i * cos_d * cos_bent_i < 0.0f) return 0.0f;
  const float ci = std::fabs(cos_smooth_i), cd = std::fabs(cos_d);
  if (cd >= 1.0f || ci >= 1.0f) return 1.0f;
  if (ci < 1e-6f) return 0.0f;
  const float alpha2 = std::clamp(0.125f * (1.0f / (cd * cd) - 1.0f), 0.0f, 1.0f);
  const float lambda = 0.5f * (std::sqrt(1.0f + alpha2 * (1.0f / (ci * ci) - 1.0f)) - 1.0f);
  return 1.0f / (1.0f + lambda);
}

}  // namespace toyrt
