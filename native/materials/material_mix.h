// Blender's Mix Shader and Add Shader of any two materials: a material slot that is not shaded
// itself but stands for two other materials of the scene (its `first` and `second`, either a mix
// again, -1 an unlinked input: black). Kept beside the material, as emission and transparency
// are, so the Material variant and a scene without mixes are untouched.
//
// The mixed closure is (1 - f) A + f B (Add: A + B), f the factor clamped to [0, 1] as Cycles
// clamps it. At a hit the integrator draws one of the two with probability proportional to its
// weight and shades only that one, its throughput multiplied by weight / probability = the sum
// of the weights (1 for a Mix, 2 for an Add): a one-sample estimator of the sum, unbiased, each
// drawn material doing its own light sampling, MIS and continuation. Nested mixes are walked down
// to a leaf with the same uniform number, rescaled at each level.
//
// The factor: a constant; an image texture's alpha or colour (Rec. 709 luminance, as Blender
// turns a colour into a float) at the hit's UV; or the view-dependent Fresnel and Layer Weight
// nodes, closed forms of the cosine between the view and the shading normal (Cycles'
// kernel/svm/fresnel.h): Fresnel F(cos, eta) with eta the node's IOR (1 / IOR seen from the
// back); Layer Weight's Fresnel output F(cos, 1 / max(1 - blend, 1e-5)) (from the back the
// inverse), its Facing output 1 - |cos|^b with b = 2 blend below 0.5, 0.5 / (1 - blend) above.
#pragma once

#include "core/math.h"
#include "core/params.h"
#include "materials/texture.h"

#include <cstdint>
#include <vector>

namespace toyrt {

enum class MixFactor : uint8_t { Constant, TextureAlpha, TextureGray, Fresnel, LayerFresnel, LayerFacing };

struct MaterialMix {
  bool active = false;  // false: the slot is a material of its own
  bool add = false;     // an Add Shader: both weights 1
  int32_t first = -1, second = -1;
  MixFactor factor = MixFactor::Constant;
  float fac = 0.5f;      // the constant (Constant), the fallback otherwise
  int32_t texture = -1;  // TextureAlpha, TextureGray: the scene's texture id
  float param = 1.45f;   // Fresnel: the IOR; LayerFresnel, LayerFacing: the blend

  // From add_material's keywords of kind 'mix': first, second (material ids, -1: black), add
  // (False), fac (0.5), fac_source ('constant', 'alpha', 'gray', 'fresnel', 'layer_fresnel',
  // 'layer_facing'), fac_texture (-1), fac_param (IOR or blend). Throws std::invalid_argument
  // for an unknown source or a texture source without a texture.
  static MaterialMix from_params(const Params& params);

  // Throws std::invalid_argument for a child id that is not -1 or another of the scene's
  // `materials`, or an unknown texture (Scene::set_mix refuses cycles).
  void check(int64_t self, size_t materials, size_t textures) const;

  bool operator==(const MaterialMix& o) const {
    return active == o.active && add == o.add && first == o.first && second == o.second && factor == o.factor &&
           fac == o.fac && texture == o.texture && param == o.param;
  }
};

// Where the factor is read: the hit's UV, the view direction wo and the shading normal ns (unit,
// ns on wo's side), and whether the ray hit the back of the surface.
struct MixPoint {
  Vec2 uv;
  Vec3 wo, ns;
  bool backfacing;
};

// The factor f of `mix` at `at`, clamped to [0, 1] (NaN: 0.5).
float mix_factor(const MaterialMix& mix, const std::vector<Texture>& textures, const MixPoint& at);

// The material a hit on slot `material` shades, drawn by `u` in [0, 1), with the throughput
// weight; leaf -1: black (the path ends). Nested mixes are followed at most kMaxMixDepth deep.
struct MixPick {
  int32_t leaf;
  float weight;
};
inline constexpr int kMaxMixDepth = 16;
MixPick pick_mixed(const std::vector<MaterialMix>& mixes, const std::vector<Texture>& textures, int32_t material,
                   const MixPoint& at, float u);

}  // namespace toyrt
