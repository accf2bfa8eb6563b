#include "materials/material_mix.h"

#include "materials/fresnel.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace toyrt {

MaterialMix MaterialMix::from_params(const Params& params) {
  MaterialMix m;
  m.active = true;
  m.first = int32_t(params.integer("first", -1));
  m.second = int32_t(params.integer("second", -1));
  m.add = params.flag("add", false);
  m.fac = float(params.number("fac", m.fac));
  m.texture = int32_t(params.integer("fac_texture", -1));
  const std::string source = params.text("fac_source", "constant");
  if (source == "constant")
    m.factor = MixFactor::Constant;
  else if (source == "alpha")
    m.factor = MixFactor::TextureAlpha;
  else if (source == "gray")
    m.factor = MixFactor::TextureGray;
  else if (source == "fresnel")
    m.factor = MixFactor::Fresnel;
  else if (source == "layer_fresnel")
    m.factor = MixFactor::LayerFresnel;
  else if (source == "layer_facing")
    m.factor = MixFactor::LayerFacing;
  else
    throw std::invalid_argument(
        "fac_source must be 'constant', 'alpha', 'gray', 'fresnel', 'layer_fresnel' or "
        "'layer_facing', got '" +
        source + "'");
  const float fallback = m.factor == MixFactor::Fresnel ? 1.45f : 0.5f;
  m.param = float(params.number("fac_param", fallback));
  if ((m.factor == MixFactor::TextureAlpha || m.factor == MixFactor::TextureGray) && m.texture < 0)
    throw std::invalid_argument("fac_source '" + source + "' needs a fac_texture");
  return m;
}

void MaterialMix::check(int64_t self, size_t materials, size_t textures) const {
  if (!active) return;
  for (const int32_t child : {first, second})
    if (child < -1 || child >= int64_t(materials) || child == self)
      throw std::invalid_argument("mix input " + std::to_string(child) +
                                  " must be -1 or another material id (the mix is " + std::to_string(self) +
                                  ", the scene has " + std::to_string(materials) + ")");
  if (texture < -1 || texture >= int64_t(textures))
    throw std::invalid_argument("unknown fac_texture id " + std::to_string(texture) + " (the scene has " +
                                std::to_string(textures) + " textures)");
}

namespace {
// Cycles' fresnel_dielectric_cos: the cosine's absolute value, eta the far side's index over the
// near side's; total internal reflection 1.
float fresnel_cos(float cos_i, float eta) { return fresnel_dielectric(std::fabs(cos_i), eta); }
}  // namespace

float mix_factor(const MaterialMix& mix, const std::vector<Texture>& textures, const MixPoint& at) {
  float f = mix.fac;
  switch (mix.factor) {
    case MixFactor::Constant:
      break;
    case MixFactor::TextureAlpha:
    case MixFactor::TextureGray: {
      const glm::vec4 t = textures[size_t(mix.texture)].lookup(at.uv);
      f = mix.factor == MixFactor::TextureAlpha ? t.w : 0.2126f * t.x + 0.7152f * t.y + 0.0722f * t.z;
      break;
    }
    case MixFactor::Fresnel: {
      const float eta = std::max(mix.param, 1e-5f);
      f = fresnel_cos(glm::dot(at.wo, at.ns), at.backfacing ? 1.0f / eta : eta);
      break;
    }
    case MixFactor::LayerFresnel: {
      const float eta = std::max(1.0f - mix.param, 1e-5f);
      f = fresnel_cos(glm::dot(at.wo, at.ns), at.backfacing ? eta : 1.0f / eta);
      break;
    }
    case MixFactor::LayerFacing: {
      f = std::fabs(glm::dot(at.wo, at.ns));
      float blend = mix.param;
      if (blend != 0.5f) {
        blend = std::clamp(blend, 0.0f, 1.0f - 1e-5f);
        blend = blend < 0.5f ? 2.0f * blend : 0.5f / (1.0f - blend);
        f = std::pow(f, blend);
      }
      f = 1.0f - f;
      break;
    }
  }
  if (!(f == f)) return 0.5f;
  return std::clamp(f, 0.0f, 1.0f);
}

MixPick pick_mixed(const std::vector<MaterialMix>& mixes, const std::vector<Texture>& textures, int32_t material,
                   const MixPoint& at, float u) {
  float weight = 1.0f;
  for (int level = 0; level < kMaxMixDepth; ++level) {
    if (material < 0 || size_t(material) >= mixes.size() || !mixes[size_t(material)].active) return {material, weight};
    const MaterialMix& mix = mixes[size_t(material)];
    const float f = mix.add ? 1.0f : mix_factor(mix, textures, at);
    const float w1 = mix.first < 0 ? 0.0f : (mix.add ? 1.0f : 1.0f - f);
    const float w2 = mix.second < 0 ? 0.0f : f;
    const float sum = w1 + w2;
    if (!(sum > 0.0f)) return {-1, 0.0f};
    // Each input with probability w / sum, weighted sum: unbiased; u is rescaled to [0, 1) within
    // the chosen part so a nested mix draws with the same number.
    const float p2 = w2 / sum;
    weight *= sum;
    if (u < p2) {
      u = std::min(u / p2, 0x1.fffffep-1f);
      material = mix.second;
    } else {
      u = std::min((u - p2) / (1.0f - p2), 0x1.fffffep-1f);
      material = mix.first;
    }
  }
  return {-1, 0.0f};  // deeper than kMaxMixDepth: black (the add-on bounds its depth below this)
}

}  // namespace toyrt
