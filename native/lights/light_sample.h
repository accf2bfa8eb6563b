// What a light sampler hands the integrator. With a sample s at shading point p and normal n,
// the direct-lighting estimate is  f(wo, s.wi) * s.radiance * |dot(n, s.wi)| / s.pdf,  after a
// shadow ray from p towards s.wi with tfar = s.distance (segments are half-open, so the light's
// own surface does not block it). s.pdf is a solid-angle density, so it can enter multiple
// importance sampling against a BSDF's pdf; evaluate_light() gives the same pdf for a direction
// found another way.
#pragma once

#include "core/math.h"

namespace toyrt {

struct LightSample {
  Vec3 point{0.0f};       // the sampled point on the light
  Vec3 wi{0.0f};          // unit direction from the shading point to `point`
  float distance = 0.0f;  // infinite for a light at infinity (a sun): the shadow ray is unbounded
  // Radiance arriving along -wi, W / (m^2 sr) per channel. For a delta light (a point light of
  // radius 0) there is no radiance: this holds its irradiance at normal incidence, I / d^2
  // (W / m^2), and pdf is 1, so the estimate above keeps the same form.
  Vec3 radiance{0.0f};
  float pdf = 0.0f;    // solid-angle density of wi (1 / sr); 0: no sample (the light cannot reach p)
  bool delta = false;  // cannot be hit by a ray, so it takes no part in MIS
  bool valid() const { return pdf > 0.0f; }
};

// A light seen along a given direction (a BSDF-sampled ray): what the ray finds on it.
struct LightEval {
  Vec3 radiance{0.0f};  // W / (m^2 sr); 0 if the ray misses the light or sees its back
  // FLT_MAX for a light at infinity (a sun's disc): seen only by rays that leave the scene.
  float distance = kInfinity;
  float pdf = 0.0f;  // the light sampler's solid-angle density for this direction
  bool hit() const { return pdf > 0.0f; }
};

}  // namespace toyrt
