// A diffuse and a glossy lobe side by side: Blender's Mix Shader (factor k: weights 1 - k and k)
// or Add Shader (weights 1 and 1) of a Diffuse BSDF and a Glossy BSDF. f = diffuse_weight x
// albedo / pi + glossy colour x GGX. The integrator takes the diffuse part's direct light as at
// a Lambert hit (where that part ends) and the glossy part's as at a glossy hit (where the path
// goes on along the lobe's sample): two estimators of the two terms, each unbiased, so the sum is
// Cycles' answer with diffuse bounces 0.
//
// Parameters (add_material('diffuse_glossy', ...)): color, texture (the diffuse part, as
// 'diffuse'), diffuse_weight (1, finite and >= 0: scales the colour or the texture),
// glossy_color ((0.8, 0.8, 0.8): the glossy part's colour, its weight included), roughness,
// shadowing (as 'glossy').
#pragma once

#include "core/params.h"
#include "materials/glossy.h"
#include "materials/lambert.h"
#include "materials/scatter.h"

#include <cstdint>

namespace toyrt {

struct DiffuseGlossy {
  static constexpr const char* kType = "diffuse_glossy";
  static constexpr const char* kParams =
      "color, texture (the diffuse part), diffuse_weight (1), glossy_color ((0.8, 0.8, 0.8)), roughness (0.5),\n"
      "shadowing ('separable' or 'correlated'): Mix or Add Shader of a Diffuse and a Glossy BSDF";
  Lambert diffuse;
  float diffuse_weight = 1.0f;  // >= 0
  Glossy glossy;

  static DiffuseGlossy from_params(const Params& params);
};

Scatter scatter(const DiffuseGlossy& m, const ShadingPoint& s, const MaterialContext& ctx);
inline int32_t texture_index(const DiffuseGlossy& m) { return m.diffuse.texture; }

}  // namespace toyrt
