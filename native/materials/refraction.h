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
// Roughness: above kDielectricMinAlpha (and for ior not within 1e-4 of 1, where refraction does not
// bend and a transmission lobe would be a delta) both answer a rough dielectric lobe
// (materials/dielectric_lobe.h, GGX or Beckmann, alpha = roughness^2) instead of specular branches; below it
// the specular answer, which the lobe converges to (materials_test).
//
// No 1 / eta^2 radiance scaling is applied on refraction: Cycles applies none, and a closed
// object scales by eta^2 entering and 1 / eta^2 leaving anyway.
#pragma once

#include "core/math.h"
#include "core/params.h"
#include "materials/dielectric_albedo.h"
#include "materials/scatter.h"

#include <cstdint>

namespace toyrt {

// Below this alpha a dielectric is specular: the lobe is within 0.06 degrees of the mirror and
// refraction directions, and its D's peak (1 / (pi alpha^2) ~ 3e5) stays well inside float.
inline constexpr float kDielectricMinAlpha = 1e-3f;

// The rough lobe's settings, shared by both: roughness (0, clamped to [0, 1]; finite), shadowing
// ('separable' 3.x, 'correlated' 4.0+), distribution ('ggx', 'beckmann': Cycles' names, lower case).
struct DielectricRoughness {
  float roughness = 0.0f;
  GgxShadowing shadowing = GgxShadowing::Separable;
  MicrofacetDistribution distribution = MicrofacetDistribution::Ggx;
};

// Parameters of both (add_material('refraction' or 'glass', ...)): ior (1.45, Blender's
// default), positive and finite; roughness and shadowing (DielectricRoughness); glass also
// fresnel ('microfacet': Cycles 4.0+, the Fresnel term of each microfacet; 'macro': 3.x, the
// shading normal's Fresnel term weighting a reflection and a refraction lobe).
struct PerfectRefraction {
  static constexpr const char* kType = "refraction";
  static constexpr const char* kParams =
      "ior (1.45), roughness (0; alpha = roughness^2), distribution ('ggx', 'beckmann'), shadowing\n"
      "('separable' 3.x, 'correlated' 4.0+), color ((1, 1, 1)): refraction without reflection, Blender's\n"
      "Refraction BSDF";
  float ior = 1.45f;  // Blender's default; must be positive and finite
  DielectricRoughness rough;
  Vec3 color{1.0f};  // the node's Color: every ray through (or mirrored by) it
  static PerfectRefraction make(float ior, DielectricRoughness rough = {}, const Vec3& color = Vec3(1.0f));
  static PerfectRefraction from_params(const Params& params);
};

struct FresnelDielectric {
  static constexpr const char* kType = "glass";
  static constexpr const char* kParams =
      "ior (1.45), roughness (0; alpha = roughness^2), distribution ('ggx', 'beckmann'), shadowing\n"
      "('separable' 3.x, 'correlated' 4.0+), fresnel ('microfacet' 4.0+, 'macro' 3.x), multiscatter (False;\n"
      "4.0+'s Multiscatter GGX: GGX with fresnel 'microfacet' only), color ((1, 1, 1)): Fresnel reflection and\n"
      "refraction, Blender's Glass BSDF";
  float ior = 1.45f;
  DielectricRoughness rough;
  bool macro_fresnel = false;
  // With macro_fresnel (3.x's two closures), the refraction's own roughness: 3.x Principled's
  // Transmission Roughness combined with its Roughness as Cycles 3.x combines them (the add-on);
  // < 0: the roughness. Not a parameter of the Glass BSDF, whose two closures share one.
  float transmit_roughness = -1.0f;
  // Multiscatter GGX (materials/dielectric_albedo.h): the id of the lobe's albedo table over
  // cos_o, made by make() (shared_dielectric_albedo); -1: single scattering (or a sharp material).
  int32_t albedo = -1;
  // Colours of the reflected and the transmitted rays: the Glass BSDF's Color on both; the
  // Principled BSDF's glass sets them per hit (principled.cpp). In [0, 1] per channel.
  Vec3 reflect_tint{1.0f};
  Vec3 transmit_tint{1.0f};
  // Throws std::invalid_argument for multiscatter with Beckmann or the macro Fresnel (Cycles has none).
  static FresnelDielectric make(float ior, DielectricRoughness rough = {}, bool macro_fresnel = false,
                                bool multiscatter = false);
  static FresnelDielectric from_params(const Params& params);
};

// The rough lobe at a hit (frame and sides as refraction's: wo's side of the geometric normal
// decides eta), or false when the material is specular there (kDielectricMinAlpha, ior ~ 1).
// transmit_roughness (Glass3x only, >= 0): the transmission's own roughness. Then the material is
// specular only where both are; a sharp reflection beside a rough refraction is the lobe of the
// smallest rough alpha, kDielectricMinAlpha, which is within 0.06 degrees of the mirror.
bool rough_dielectric(const ShadingPoint& s, float ior, const DielectricRoughness& rough, DielectricKind kind,
                      DielectricLobe* lobe, float transmit_roughness = -1.0f);

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
