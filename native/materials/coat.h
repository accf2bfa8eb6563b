// Blender 4.0+'s Principled Coat as Cycles 4.0+ layers it over the rest of the BSDF
// (kernel/svm/closure.h and kernel/closure/bsdf_microfacet.h, read for the facts):
//   - The coat is a GGX lobe with the plain dielectric Fresnel of the coat's IOR, and Cycles
//     always gives it the multiscatter energy compensation (its Fresnel set-up does, whatever the
//     Principled's distribution): the single-scatter lobe times 1 + F_ms (1 - E) / E with
//     Fss the IOR's average Fresnel (materials/multiscatter.h).
//   - What lies below is scaled by 1 - Coat Weight x the coat closure's estimated albedo at wo:
//     its weight (the compensation's share that Cycles keeps there, E (1 + F_ms (1 - E) / E))
//     times mix(F0, 1, s), s the table's mean blend of the IOR's Fresnel curve over the lobe's
//     reflections (sampling/ggx_albedo.h), the same estimate as the specular layer's. A rough
//     coat at grazing angles reflects less than the Fresnel term at wo, so it leaves more below.
//   - The layers below are also tinted by mix(1, Coat Tint ^ d, Coat Weight), d = 1 / cos of wo
//     refracted into the coat: Beer's law along the path through a coat of unit thickness.
// The same numbers serve the render (materials/principled.cpp) and the Glossy Color pass
// (render/glossy_color.cpp), so the pass and the image cannot disagree on the coat.
#pragma once

#include "core/math.h"
#include "materials/fresnel.h"
#include "materials/multiscatter.h"
#include "sampling/ggx_albedo.h"

#include <algorithm>
#include <cmath>

namespace toyrt {

struct CoatLayer {
  float lobe_scale = 1.0f;  // the coat lobe's energy compensation, >= 1
  float albedo = 0.0f;      // Coat Weight x the coat's estimated albedo at wo, in [0, 1]
  Vec3 below{1.0f};         // what the layers under the coat keep: (1 - albedo) x the tint's share
};

// weight in [0, 1], roughness in [0, 1], eta >= 1 (its F0 `f0`), cos_o of wo about the coat's
// normal on wo's side.
inline CoatLayer coat_layer(float weight, float roughness, float eta, float f0, const Vec3& tint, float cos_o) {
  CoatLayer layer;
  const float mu = std::clamp(cos_o, 0.0f, 1.0f);
  layer.lobe_scale = multiscatter_scale(roughness, mu, Vec3(fresnel_dielectric_average(eta))).x;
  // Cycles' estimate reads the table for an IOR above 1; at 1 the coat reflects nothing.
  const float reflectance = eta > 1.0f ? f0 + (1.0f - f0) * ggx_fresnel_blend(roughness, mu, eta) : 0.0f;
  layer.albedo = std::clamp(weight * layer.lobe_scale * ggx_albedo(roughness, mu) * reflectance, 0.0f, 1.0f);
  layer.below = Vec3(1.0f - layer.albedo);
  if (tint != Vec3(1.0f)) {
    const float sin2_t = (1.0f - mu * mu) / (eta * eta);
    const float depth = 1.0f / std::sqrt(std::max(1.0f - sin2_t, 1e-6f));
    layer.below *= glm::mix(Vec3(1.0f), glm::pow(glm::max(tint, Vec3(0.0f)), Vec3(depth)), weight);
  }
  return layer;
}

}  // namespace toyrt
