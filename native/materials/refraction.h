// Specular dielectrics: PerfectRefraction (the seed's material, Blender's Refraction BSDF with
// roughness 0, except that total internal reflection mirrors) and FresnelDielectric (Blender's
// Glass BSDF with roughness 0: reflection with probability F, refraction otherwise).
//
// Sides and normals. wo points away from the surface (back along the incoming ray). The
// geometric normal ng decides the side: the ray enters the object when wo is on ng's side
// (eta = 1 / ior) and leaves it otherwise (eta = ior). The shading (smooth) normal ns, first
// turned to ng's hemisphere (so flipped vertex normals cannot swap inside and outside), bends
// the ray. Where the two disagree we fall back to ng: when wo lies below ns's tangent plane
// (cos_i <= 0 against ns, possible near silhouettes of smooth meshes), or when the direction
// bent by ns leaves on the wrong side of the real surface (a refracted ray above it, a reflected
// one below it), the result is recomputed with ng. The returned direction is therefore always
// on the geometrically right side, at the price of a small discontinuity where the fallback
// starts.
//
// No 1 / eta^2 radiance scaling is applied on refraction: Cycles applies none, and a closed
// object scales by eta^2 entering and 1 / eta^2 leaving anyway.
#pragma once

#include "core/math.h"
#include "core/params.h"
#include "materials/scatter.h"

#include <cstdint>

namespace toyrt {

// Parameters of both (add_material('refraction' or 'glass', ...)): ior (1.45, Blender's
// default), positive and finite.
struct PerfectRefraction {
  static constexpr const char* kType = "refraction";
  static constexpr const char* kParams = "ior (1.45): perfect refraction, Blender's Refraction BSDF";
  float ior = 1.45f;  // Blender's default; must be positive and finite
  static PerfectRefraction make(float ior);
  static PerfectRefraction from_params(const Params& params);
};

struct FresnelDielectric {
  static constexpr const char* kType = "glass";
  static constexpr const char* kParams = "ior (1.45): Fresnel reflection and refraction, Blender's Glass BSDF";
  float ior = 1.45f;
  static FresnelDielectric make(float ior);
  static FresnelDielectric from_params(const Params& params);
};

// Mirror of wo about n: 2 (wo . n) n - wo.
inline Vec3 reflect(const Vec3& wo, const Vec3& n) { return 2.0f * glm::dot(wo, n) * n - wo; }

// Snell's law: refracts wo (on n's side, unit) through an interface with relative index
// eta = n_i / n_t; false under total internal reflection.
inline bool refract(const Vec3& wo, const Vec3& n, float eta, Vec3* wt) {
  const float cos_i = glm::dot(wo, n);
  const float sin2_t = eta * eta * std::max(0.0f, 1.0f - cos_i * cos_i);
  if (sin2_t >= 1.0f) return false;
  const float cos_t = std::sqrt(1.0f - sin2_t);
  *wt = glm::normalize(-eta * wo + (eta * cos_i - cos_t) * n);
  return true;
}

SpecularSample sample(const PerfectRefraction& m, const Vec3& wo, const Vec3& ng, const Vec3& ns);
// u: one uniform number choosing between reflection and refraction.
SpecularSample sample(const FresnelDielectric& m, const Vec3& wo, const Vec3& ng, const Vec3& ns, float u);

// Both branches at once, for splitting: the reflected and the refracted direction, each with
// its Fresnel weight in `probability` (F and 1 - F, summing to 1), or one branch of weight 1
// when only one exists (total internal reflection, or F = 0). Returns the branch count (1 or 2).
int split(const FresnelDielectric& m, const Vec3& wo, const Vec3& ng, const Vec3& ns, SpecularSample out[2]);

// The integrator's interface (materials/scatter.h). Refraction always continues along one
// branch; glass splits when ctx.split, and otherwise draws ctx.uniform() to choose.
Scatter scatter(const PerfectRefraction& m, const ShadingPoint& s, const MaterialContext& ctx);
Scatter scatter(const FresnelDielectric& m, const ShadingPoint& s, const MaterialContext& ctx);
inline int32_t texture_index(const PerfectRefraction&) { return -1; }
inline int32_t texture_index(const FresnelDielectric&) { return -1; }

}  // namespace toyrt
