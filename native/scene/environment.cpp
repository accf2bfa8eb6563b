#include "scene/environment.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace toyrt {
namespace {

Vec2 direction_to_uv(const Vec3& d) {
  const float u = 0.5f - std::atan2(d.y, d.x) / (2.0f * kPi);
  // sqrt, not std::hypot: d is a unit vector (nothing to overflow), and hypotf would raise the
  // wheels' glibc floor from 2.34 to 2.35 (docs/install.md).
  const float v = 0.5f + std::atan2(d.z, std::sqrt(d.x * d.x + d.y * d.y)) / kPi;
  return Vec2(u - std::floor(u), std::clamp(v, 0.0f, 1.0f));
}

// The inverse: v = 1 is up (theta = 0 from +Z).
Vec3 uv_to_direction(const Vec2& uv, float& sin_theta) {
  const float phi = (0.5f - uv.x) * 2.0f * kPi;
  const float theta = (1.0f - uv.y) * kPi;
  sin_theta = std::sin(theta);
  return Vec3(sin_theta * std::cos(phi), sin_theta * std::sin(phi), std::cos(theta));
}

float luminance(const glm::vec4& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

}  // namespace

Environment make_environment(int32_t texture, const Texture& image, const Vec3& strength, const glm::mat3& to_map) {
  if (!is_finite(strength) || glm::any(glm::lessThan(strength, Vec3(0.0f))))
    throw std::invalid_argument("environment: strength must be finite and >= 0");
  const float det = glm::determinant(to_map);
  if (!std::isfinite(det) || det == 0.0f) throw std::invalid_argument("environment: the mapping is singular");
  Environment env;
  env.texture = texture;
  env.strength = strength;
  env.to_map = to_map;
  // The sampling grid: at most kMaxSamplingWidth columns and half as many rows, each cell
  // weighted by the brightest texel it covers or borders. The border counts because bilinear
  // lookups spread a texel into its neighbours' area: a one-texel sun weighted by its own cell
  // alone would leave its halo to cells sampled as dim sky (fireflies, and slow convergence).
  const int w = std::min(image.width, Environment::kMaxSamplingWidth);
  const int h = std::max(1, std::min(image.height, Environment::kMaxSamplingWidth / 2));
  std::vector<float> weights(size_t(w) * size_t(h), 0.0f);
  for (int y = 0; y < h; ++y) {
    const int y0 = int(int64_t(y) * image.height / h), y1 = std::max(y0 + 1, int(int64_t(y + 1) * image.height / h));
    // Row y's centre, as the sine of its angle from the pole: cells near the poles cover less.
    const float sin_theta = std::sin((1.0f - (y + 0.5f) / float(h)) * kPi);
    for (int x = 0; x < w; ++x) {
      const int x0 = int(int64_t(x) * image.width / w), x1 = std::max(x0 + 1, int(int64_t(x + 1) * image.width / w));
      float brightest = 0.0f;
      for (int j = std::max(0, y0 - 1); j <= std::min(image.height - 1, y1); ++j)
        for (int i = x0 - 1; i <= x1; ++i)  // columns wrap around (the map is periodic in u)
          brightest = std::max(brightest, luminance(image.texel((i + image.width) % image.width, j)));
      weights[size_t(y) * w + x] = brightest * sin_theta;
    }
  }
  env.sampling = Distribution2D::build(weights, w, h);
  return env;
}

Vec3 environment_radiance(const Environment& env, const Texture& image, const Vec3& wi) {
  Vec2 uv = direction_to_uv(glm::normalize(env.to_map * wi));
  // Columns wrap around; rows must not: the texture's repeat would blend the top row with the
  // bottom one over the poles. Clamped to the outer rows' centres, as Cycles' lookup extends them.
  const float half_row = 0.5f / float(image.height);
  uv.y = std::clamp(uv.y, half_row, 1.0f - half_row);
  return Vec3(image.lookup(uv)) * env.strength;
}

EnvironmentSample sample_environment(const Environment& env, const Texture& image, const Vec2& u) {
  EnvironmentSample s;
  float pdf_uv = 0.0f;
  const Vec2 uv = env.sampling.sample(u, pdf_uv);
  float sin_theta = 0.0f;
  const Vec3 d = uv_to_direction(uv, sin_theta);
  if (!(sin_theta > 0.0f) || !(pdf_uv > 0.0f)) return s;
  // The map's frame back to the world: to_map may scale, so normalise.
  const Vec3 wi = glm::inverse(env.to_map) * d;
  const float len = glm::length(wi);
  if (!(len > 0.0f)) return s;
  s.wi = wi / len;
  s.pdf = environment_pdf(env, s.wi);
  s.radiance = environment_radiance(env, image, s.wi);
  return s;
}

float environment_pdf(const Environment& env, const Vec3& wi) {
  const Vec3 d = glm::normalize(env.to_map * wi);
  const float sin_theta = std::sqrt(std::max(0.0f, 1.0f - d.z * d.z));
  if (!(sin_theta > 0.0f)) return 0.0f;
  // A non-rotation mapping changes solid angles too: its Jacobian |det M| / |M wi|^3.
  const Vec3 m = env.to_map * wi;
  const float len = glm::length(m);
  const float jacobian = std::fabs(glm::determinant(env.to_map)) / (len * len * len);
  return env.sampling.pdf(direction_to_uv(d)) / (2.0f * kPi * kPi * sin_theta) * jacobian;
}

}  // namespace toyrt
