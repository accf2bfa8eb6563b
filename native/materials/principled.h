// Blender 4.0+'s Principled BSDF, dielectric (Metallic 0, Transmission 0): a Lambert base under a
// GGX specular layer, as Cycles 4.0+ builds it.
//   - The layer's Fresnel is the interface's own curve blended from F0 = F0(IOR) x 2 Specular IOR
//     Level (the IOR that gives that F0 shapes the curve) times Specular Tint, to 1 at grazing
//     (materials/glossy_lobe.h). IOR 1 (or Level 0) leaves no layer: plain Lambert.
//   - The base is scaled by what the layer leaves, 1 - max over channels of the layer's
//     directional albedo at wo, estimated as Cycles does from a table (sampling/ggx_albedo.h):
//     energy layering without a random walk, so the sum reflects at most what came in.
//   - Multiscatter GGX (Principled's default distribution in 4.0+) adds the microfacets' inter-
//     reflections back to the layer (materials/multiscatter.h); plain GGX does not.
// With metallic 1 there is no base: the layer is a metal whose F0 is the base colour (a
// texture's at the hit), 4.0+'s F82-tint Fresnel (Specular Tint the colour at 82 degrees relative
// to Schlick's), or 3.x's dielectric curve blend from the base colour. Between 0 and 1, 4.0+
// mixes the metal and the dielectric (one of the two lobes drawn per hit); 3.x blends one
// lobe's F0 from the dielectric's to the base colour and weights the base 1 - metallic.
// Blender 3.x's Principled (layered False, shadowing 'separable') adds the same kind of layer to
// a base it leaves whole: F0 = 0.08 Specular times its tint colour, the curve of the IOR with
// that F0 (the add-on converts), over Burley's diffuse (burley True: materials/burley_diffuse.h),
// whose value the integrator takes per light direction.
// The integrator sees what a Mix of Diffuse and Glossy gives it (scatter.h's Glossy answer with a
// diffuse part), so the base's direct light is a Lambert hit's and the layer's is MIS'd.
//
// Parameters (add_material('principled', ...)): color ((0.8, 0.8, 0.8)), texture (the base
// colour), roughness (0.5, clamped to [0, 1]), ior (1.45, every kind's; > 0), specular_ior_level (0.5, >= 0),
// specular_tint ((1, 1, 1), >= 0), multiscatter (True), layered (True; False: 3.x), shadowing
// ('correlated', 4.0+; 'separable', 3.x), metallic (0, clamped to [0, 1]), burley (False; True:
// 3.x's Burley diffuse base instead of Lambert), transmission (0, clamped to [0, 1]) and
// transmission_ior (the ior): the share of a glass beside the opaque parts, below; with layered
// False, refraction_roughness (the roughness): its refraction's own roughness (3.x's Transmission
// Roughness, combined with the Roughness by the add-on as Cycles 3.x combines them).
//
// Transmission (Cycles' order: the metal takes Metallic, the glass (1 - Metallic) Transmission,
// the dielectric layer and base what is left): the glass is the Glass BSDF's rough dielectric of
// the same roughness and masking (materials/refraction.h; 3.x's Fresnel-weighted lobe pair, 4.0+'s
// Fresnel per microfacet with Multiscatter GGX as chosen), drawn with probability its share on the
// lobe-choice number; otherwise the opaque parts answer as above with the base scaled so that its
// expectation keeps its weight. Its colours are Cycles' per version, from the base colour at the
// hit (principled.cpp): 4.0+ sqrt(base) on each transmission and Specular Tint on the reflection,
// 3.x the base colour on the refraction.
//
// Coat (4.0+): coat_weight (0, clamped to [0, 1]),
// coat_roughness (0.03), coat_ior (1.5, >= 1), coat_tint ((1, 1, 1)): a GGX dielectric layer over
// everything opaque, as Cycles 4.0+ puts it there (materials/coat.h): its lobe weighted
// coat_weight and always energy-compensated, the layers below scaled by 1 - coat_weight x
// Cycles' estimate of its albedo (as the specular layer scales the base) and tinted by
// mix(1, coat_tint ^ d, coat_weight), d = 1 / cos of wo refracted into the coat (Beer's law
// over the path through a coat of unit thickness). One of the coat's lobe and
// the layers' lobes is drawn per hit (the coat with probability coat_weight / 2), its weight
// divided by that probability; the diffuse base gets its direct light on either draw. The glass
// of Transmission is not coated (noted by the add-on).
// With layered False (3.x) coat_weight and coat_roughness are 3.x's Clearcoat and Clearcoat
// Roughness: Cycles 3.x's GTR1 lobe added beside the rest, nothing attenuated (materials/clearcoat.h).
#pragma once

#include "core/params.h"
#include "materials/glossy.h"
#include "materials/lambert.h"
#include "materials/refraction.h"
#include "materials/scatter.h"

#include <cstdint>

namespace toyrt {

struct Principled {
  static constexpr const char* kType = "principled";
  static constexpr const char* kParams =
      "color, texture (the base colour), roughness (0.5), ior (1.45), specular_ior_level (0.5),\n"
      "specular_tint ((1, 1, 1)), multiscatter (True), layered (True; False: Blender 3.x's sum),\n"
      "shadowing ('correlated'; 'separable': 3.x), metallic (0), burley (False; True: 3.x's diffuse),\n"
      "transmission (0), transmission_ior (the ior), refraction_roughness (the roughness; 3.x), coat_weight (0),\n"
      "coat_roughness (0.03), coat_ior (1.5), coat_tint ((1, 1, 1); with layered False: 3.x's Clearcoat and\n"
      "its roughness): the Principled BSDF";
  Lambert base;
  float roughness = 0.5f;  // in [0, 1]
  bool multiscatter = true;
  bool layered = true;  // the base scaled by what the layer leaves (4.0+), or whole (3.x)
  bool burley = false;  // the base is Burley's diffuse (3.x), not Lambert
  GgxShadowing shadowing = GgxShadowing::HeightCorrelated;
  float metallic = 0.0f;  // in [0, 1]; 1: a metal of the base colour, no base
  Vec3 specular_tint{1.0f};
  float transmission = 0.0f;  // in [0, 1]; > 0: `glass` takes (1 - metallic) transmission
  FresnelDielectric glass;
  float coat = 0.0f;  // coat_weight, in [0, 1]; 0: no coat
  float coat_roughness = 0.03f;
  float coat_eta = 1.5f;  // >= 1
  float coat_f0 = 0.04f;  // F0(coat_eta)
  Vec3 coat_tint{1.0f};
  // Derived once from ior, specular_ior_level and specular_tint:
  float eta = 1.5f;      // the IOR whose curve shapes the Fresnel term; 1: no layer
  Vec3 f0{0.04f};        // the layer's reflectance at normal incidence, tint included, <= 1
  float eta_f0 = 0.04f;  // F0(eta)
  Vec3 fss{0.0f};        // the layer's average single-bounce Fresnel (multiscatter)

  static Principled from_params(const Params& params);
};

Scatter scatter(const Principled& m, const ShadingPoint& s, const MaterialContext& ctx);

// The lobes scatter() draws from at a hit, whole (not divided by a draw's probability), for the
// Glossy Color pass (render/glossy_color.h): the metal of base colour `base_color`, and the
// dielectric specular layer (none where eta is 1).
GlossyLobe principled_metal_lobe(const Principled& m, const ShadingPoint& s, const Vec3& base_color);
GlossyLobe principled_specular_lobe(const Principled& m, const ShadingPoint& s);
inline int32_t texture_index(const Principled& m) { return m.base.texture; }

}  // namespace toyrt
