#include "materials/texture.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace toyrt {
namespace {

void check_shape(int width, int height, int channels, size_t size) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("texture: width and height must be positive");
  if (channels != 3 && channels != 4) throw std::invalid_argument("texture: channels must be 3 (RGB) or 4 (RGBA)");
  if (size != size_t(width) * size_t(height) * size_t(channels))
    throw std::invalid_argument(
        "texture: expected width * height * channels = " + std::to_string(size_t(width) * height * channels) +
        " values, got " + std::to_string(size));
}

template <class T, class ToUnit>
Texture make(int width, int height, int channels, const std::vector<T>& data, ColorEncoding encoding, ToUnit to_unit,
             bool decode_after_filter) {
  check_shape(width, height, channels, data.size());
  Texture t;
  t.width = width;
  t.height = height;
  t.channels = channels;
  t.texels.resize(data.size());
  t.decode_after_filter = decode_after_filter && encoding == ColorEncoding::Srgb;
  for (size_t i = 0; i < data.size(); ++i) {
    const float v = to_unit(data[i]);
    if (!std::isfinite(v)) throw std::invalid_argument("texture: values must be finite");
    const bool alpha = channels == 4 && i % 4 == 3;
    t.texels[i] = encoding == ColorEncoding::Srgb && !alpha && !t.decode_after_filter ? srgb_to_linear(v) : v;
  }
  return t;
}

// Repeat: any integer to [0, n).
int wrap(int i, int n) {
  const int r = i % n;
  return r < 0 ? r + n : r;
}

}  // namespace

Texture Texture::from_floats(int width, int height, int channels, const std::vector<float>& data,
                             ColorEncoding encoding) {
  return make(
      width, height, channels, data, encoding, [](float v) { return v; }, false);
}

Texture Texture::from_bytes(int width, int height, int channels, const std::vector<uint8_t>& data,
                            ColorEncoding encoding) {
  return make(
      width, height, channels, data, encoding, [](uint8_t v) { return float(v) / 255.0f; }, true);
}

namespace {
glm::vec4 stored(const Texture& tex, int x, int y) {
  const float* t = &tex.texels[(size_t(y) * tex.width + x) * tex.channels];
  return glm::vec4(t[0], t[1], t[2], tex.channels == 4 ? t[3] : 1.0f);
}
glm::vec4 decoded(const Texture& tex, glm::vec4 c) {
  if (!tex.decode_after_filter) return c;
  return glm::vec4(srgb_to_linear(c.x), srgb_to_linear(c.y), srgb_to_linear(c.z), c.w);  // alpha stays linear
}
}  // namespace

glm::vec4 Texture::texel(int x, int y) const { return decoded(*this, stored(*this, x, y)); }

glm::vec4 Texture::lookup(const Vec2& uv) const {
  float u = std::isfinite(uv.x) ? uv.x : 0.0f, v = std::isfinite(uv.y) ? uv.y : 0.0f;
  // Wrap first, so huge coordinates cannot overflow the integer texel index.
  u -= std::floor(u);
  v -= std::floor(v);
  const float x = u * float(width) - 0.5f, y = v * float(height) - 0.5f;
  const float fx = std::floor(x), fy = std::floor(y);
  const float tx = x - fx, ty = y - fy;
  const int x0 = wrap(int(fx), width), x1 = wrap(int(fx) + 1, width);
  const int y0 = wrap(int(fy), height), y1 = wrap(int(fy) + 1, height);
  const glm::vec4 bottom = stored(*this, x0, y0) * (1.0f - tx) + stored(*this, x1, y0) * tx;
  const glm::vec4 top = stored(*this, x0, y1) * (1.0f - tx) + stored(*this, x1, y1) * tx;
  return decoded(*this, bottom * (1.0f - ty) + top * ty);
}

}  // namespace toyrt
