// The glossy material: Blender's Glossy BSDF (GGX or Beckmann), or a Principled BSDF with Metallic 1 reduced
// to its base colour and roughness. f = colour x D G2 / (4 cos_o cos_i) (sampling/ggx.h): the
// colour stands for the Fresnel term at every angle, as in Blender's Glossy BSDF, which tints by
// its colour with no Fresnel falloff.
//
// Parameters (add_material('glossy', ...)): color ((0.8, 0.8, 0.8), linear RGB >= 0), roughness
// (0.5, Blender's default; finite, clamped to [0, 1] as Cycles does), shadowing ('separable',
// Blender 3.x's masking-shadowing, or 'correlated', 4.0+'s), multiscatter (False; True:
// Multiscatter GGX, Blender 4.0+'s energy compensation, materials/multiscatter.h), distribution
// ('ggx'; 'beckmann': sampling/beckmann.h, with the same masking choice and no compensation).
#pragma once

#include "core/params.h"
#include "materials/scatter.h"

#include <cstdint>

namespace toyrt {

struct Glossy {
  static constexpr const char* kType = "glossy";
  static constexpr const char* kParams =
      "color (linear RGB, (0.8, 0.8, 0.8)), roughness (0.5, clamped to [0, 1]; alpha = roughness^2),\n"
      "shadowing ('separable': Blender 3.x, 'correlated': 4.0+), multiscatter (False; 4.0+'s Multiscatter GGX),\n"
      "distribution ('ggx'; 'beckmann', without multiscatter): microfacet reflection, Blender's Glossy BSDF";
  Vec3 color{0.8f};
  float roughness = 0.5f;  // in [0, 1]
  GgxShadowing shadowing = GgxShadowing::Separable;
  bool multiscatter = false;
  MicrofacetDistribution distribution = MicrofacetDistribution::Ggx;

  // Throws std::invalid_argument for a non-finite roughness, an unknown shadowing name, or
  // Multiscatter with Beckmann (Cycles compensates GGX only).
  static Glossy make(const Vec3& color, float roughness, GgxShadowing shadowing, bool multiscatter = false,
                     MicrofacetDistribution distribution = MicrofacetDistribution::Ggx);
  static Glossy from_params(const Params& params);
};

// A lobe at the hit with its frame on wo's side, as the integrator orients its light samples;
// where wo is below the shading normal's tangent plane (silhouettes of smooth meshes) the lobe sits
// on the geometric normal. Tint 0 and no Fresnel: the material fills them in.
GlossyLobe oriented_lobe(const ShadingPoint& s, float roughness, GgxShadowing shadowing);

// The `shadowing` parameter ('separable' by default); throws std::invalid_argument for another name.
GgxShadowing shadowing_from_params(const Params& params);

Scatter scatter(const Glossy& m, const ShadingPoint& s, const MaterialContext& ctx);
inline int32_t texture_index(const Glossy&) { return -1; }

}  // namespace toyrt
