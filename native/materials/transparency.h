// How much of a surface the rays pass through: Cycles' transparent closure beside a material's
// BSDF. Kept beside the material, as emission is (materials/emission.h), because any shader can
// be cut out: Principled BSDF's Alpha, a Transparent BSDF alone, or a Mix Shader of a Transparent
// BSDF and another shader (the leaf cut-out, its factor an image's alpha or colour).
//
// At a hit, the surface is the material's BSDF with weight `opacity` o and a transparent
// closure with weight (1 - o) x color (the Transparent BSDF's colour; white for Principled
// Alpha). o is a constant or a channel of a texture at the hit's UV (an image's alpha, or its
// colour as Blender turns a colour into a factor: Rec. 709 luminance), optionally 1 - that
// value (the Transparent BSDF in a Mix Shader's second input). o is clamped to [0, 1]; a NaN
// texel or constant counts as opaque (1).
#pragma once

#include "core/math.h"
#include "materials/texture.h"

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace toyrt {

enum class OpacityChannel : uint8_t { Alpha, Gray };

struct MaterialTransparency {
  Vec3 color{1.0f};      // the transparent closure's colour, >= 0
  float opacity = 1.0f;  // the constant, when texture < 0
  int32_t texture = -1;  // index into the scene's textures; -1: the constant
  OpacityChannel channel = OpacityChannel::Alpha;
  bool invert = false;  // o = 1 - the value read

  // Whether any ray can pass: a constant opacity of 1 without a texture is an opaque material,
  // which the integrator treats as if it had no transparency at all.
  bool transparent() const { return texture >= 0 || !(opacity >= 1.0f) || invert; }
  bool operator==(const MaterialTransparency& o) const {
    return color == o.color && (opacity == o.opacity || (opacity != opacity && o.opacity != o.opacity)) &&
           texture == o.texture && channel == o.channel && invert == o.invert;
  }

  // Throws std::invalid_argument for a non-finite or negative colour, or a texture id that is
  // not -1 or below `textures` (the scene's count).
  void check(size_t textures) const {
    if (!is_finite(color) || glm::any(glm::lessThan(color, Vec3(0.0f))))
      throw std::invalid_argument("transparent_color must be finite and >= 0");
    if (texture < -1 || texture >= int64_t(textures))
      throw std::invalid_argument("unknown opacity_texture id " + std::to_string(texture) + " (the scene has " +
                                  std::to_string(textures) + " textures)");
  }

  // The BSDF's weight o at texture coordinates uv, in [0, 1].
  float opacity_at(const std::vector<Texture>& textures, const Vec2& uv) const {
    float v = opacity;
    if (texture >= 0) {
      const glm::vec4 t = textures[size_t(texture)].lookup(uv);
      v = channel == OpacityChannel::Alpha ? t.w : 0.2126f * t.x + 0.7152f * t.y + 0.0722f * t.z;
    }
    if (invert) v = 1.0f - v;
    if (!(v == v)) return 1.0f;  // NaN: opaque, a defined answer
    return v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
  }
};

}  // namespace toyrt
