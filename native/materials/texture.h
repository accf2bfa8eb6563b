// Image textures as Blender stores them: rows bottom-up (row 0 is v = 0, the order of
// bpy.types.Image.pixels), RGB or RGBA, held as linear floats. sRGB-encoded images (8-bit or
// float) are decoded once at load with the exact sRGB transfer function (IEC 61966-2-1, the
// piecewise curve Blender's srgb_to_linearrgb uses); alpha is never encoded.
//
// Lookups are bilinear with repeat wrapping, texel (i, j) centred at ((i + 0.5) / width,
// (j + 0.5) / height), Cycles' "Linear" interpolation and "Repeat" extension: at u = 0 (or 1) the
// lookup is halfway between the last and the first column.
#pragma once

#include "core/math.h"
#include "sampling/warp.h"

#include <cmath>
#include <cstdint>
#include <vector>

namespace toyrt {

enum class ColorEncoding { Linear, Srgb };

struct Texture {
  int width = 0, height = 0, channels = 0;  // channels: 3 or 4
  // width * height * channels, row 0 at the bottom: linear, or, for 8-bit sRGB images, still
  // sRGB-encoded (decode_after_filter).
  std::vector<float> texels;
  // 8-bit sRGB images are filtered in their encoded values and decoded afterwards, as Cycles does
  // (measured: halfway between a black and a white texel Cycles gives srgb_to_linear(0.5) = 0.214,
  // not 0.5). Float images are decoded at load.
  bool decode_after_filter = false;

  // Throw std::invalid_argument for non-positive sizes, channels other than 3 or 4, a data size
  // that does not match, or non-finite floats.
  static Texture from_floats(int width, int height, int channels, const std::vector<float>& data,
                             ColorEncoding encoding);
  static Texture from_bytes(int width, int height, int channels, const std::vector<uint8_t>& data,
                            ColorEncoding encoding);

  glm::vec4 texel(int x, int y) const;  // column x, row y from the bottom, linear; alpha 1 for RGB
  glm::vec4 lookup(const Vec2& uv) const;
};

// sRGB-encoded value to linear (negative inputs give 0, as in Blender).
inline float srgb_to_linear(float c) {
  if (c < 0.04045f) return c < 0.0f ? 0.0f : c / 12.92f;
  return std::pow((c + 0.055f) / 1.055f, 2.4f);
}

}  // namespace toyrt
