// The world's Environment Texture: an equirectangular image (one of the scene's textures) times
// a strength, seen by rays that leave the scene and lighting surfaces as a light at infinity.
//
// Directions map to the image as Blender's Environment Texture does (equirectangular): in the
// map's frame (the world direction through `to_map`: the Mapping node's rotation and scale),
//     u = 0.5 - atan2(d.y, d.x) / (2 pi),   v = 0.5 + atan2(d.z, hypot(d.x, d.y)) / pi,
// so the image's centre column looks along -X and its top row up (+Z); image rows are stored
// from the bottom (v = 0).
//
// Importance sampling: a piecewise-constant density over a grid of at most kMaxSamplingWidth x
// kMaxSamplingWidth / 2 cells, weight = the brightest luminance in and around the cell (bilinear
// lookups spread each texel over its neighbours) x sin(theta), so bright regions (a sun in the sky) are found by few
// samples; the density in solid angle is pdf(u, v) / (2 pi^2 sin(theta)). The integrator combines it with cosine
// sampling by multiple importance sampling, so regions the grid under-weights are still covered.
#pragma once

#include "materials/texture.h"
#include "sampling/distribution_2d.h"

#include <cstdint>

namespace toyrt {

struct Environment {
  static constexpr int kMaxSamplingWidth = 1024;

  int32_t texture = -1;     // the scene's texture; -1: no environment (a constant background)
  Vec3 strength{1.0f};      // the Background node's strength (times its colour, if constant)
  glm::mat3 to_map{1.0f};   // world direction -> the map's frame
  Distribution2D sampling;  // over the grid described above

  bool active() const { return texture >= 0; }
};

// Builds the environment of `image` (a scene texture, id `texture`), or throws
// std::invalid_argument for a non-finite or negative strength, or a singular matrix.
Environment make_environment(int32_t texture, const Texture& image, const Vec3& strength, const glm::mat3& to_map);

// Radiance arriving from unit world direction wi (the map times the strength).
Vec3 environment_radiance(const Environment& env, const Texture& image, const Vec3& wi);

struct EnvironmentSample {
  Vec3 wi{0.0f};
  Vec3 radiance{0.0f};
  float pdf = 0.0f;  // solid angle; 0: no sample
};
EnvironmentSample sample_environment(const Environment& env, const Texture& image, const Vec2& u);
float environment_pdf(const Environment& env, const Vec3& wi);  // solid-angle density of wi

}  // namespace toyrt
