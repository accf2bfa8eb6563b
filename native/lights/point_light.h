// Blender's point light in Cycles' units: power P in watts, times the colour per channel, radiated
// evenly in all directions, so the radiant intensity is I = P colour / (4 pi) W/sr and a surface
// at distance r facing it at angle theta receives E = I cos(theta) / r^2 (BLENDER_UNITS.md:
// 100 W at 1 m gives a white Lambert pixel of I / pi = 2.533).
//
// Radius 0 is a delta light (hard shadows). Radius R > 0 is a sphere with uniform radiance L,
// sampled uniformly by solid angle over the cone it subtends (soft shadows). L follows from
// equal power: a sphere seen from any direction has projected area pi R^2, so its intensity is
// L pi R^2; setting that equal to P / (4 pi) gives
//     L = P colour / (4 pi * pi R^2) = P colour / (4 pi^2 R^2).
// (Check: a Lambertian surface emits pi L per unit area, times 4 pi R^2 of surface, which is P.)
// Where the whole sphere lies above the receiver's tangent plane its irradiance is
// pi L sin^2(theta_max) cos(theta) = I cos(theta) / r^2 exactly, the point light's: the two only
// differ close to the sphere and in their shadows.
//
// Parameters (add_light('POINT', ...), Blender's names): position ((0, 0, 0), m), power (10 W),
// color ((1, 1, 1), linear RGB), radius (0 m: shadow_soft_size; 0 is a delta light, hard
// shadows): PointLight::Settings.
#pragma once

#include "core/params.h"
#include "lights/light_context.h"
#include "lights/light_sample.h"
#include "sampling/warp.h"

namespace toyrt {

struct PointLight {
  static constexpr const char* kType = "POINT";  // Blender's light type
  static constexpr const char* kParams =
      "position (m, (0, 0, 0)), power (W, 10), color (linear RGB, (1, 1, 1)), radius (m, 0: hard shadows)";

  // Blender's settings, with the defaults of a new point light (radius 0: hard shadows).
  struct Settings {
    Vec3 position{0.0f};  // m
    float power = 10.0f;  // W
    Vec3 color{1.0f};     // linear RGB
    float radius = 0.0f;  // m
  };

  Vec3 position{0.0f};
  float radius = 0.0f;   // m; 0: a delta light
  Vec3 intensity{0.0f};  // I = P colour / (4 pi), W/sr
  Vec3 radiance{0.0f};   // of the sphere's surface, I / (pi R^2); 0 when radius is 0

  // Blender's settings: location, power (W), colour (linear RGB), radius (shadow_soft_size, m).
  // Throws std::invalid_argument for non-finite values, negative power, colour or radius.
  static PointLight make(const Vec3& position, float power, const Vec3& color, float radius = 0.0f);
  // From Params named as Settings' members.
  static PointLight from_params(const Params& params);
};

// A direction towards the light from shading point p (u: two uniform numbers, used for R > 0).
LightSample sample(const PointLight& light, const Vec3& p, const Vec2& u, const LightContext& ctx = {});
// The sphere along direction wi from p (nothing for radius 0: a delta light cannot be hit).
LightEval evaluate(const PointLight& light, const Vec3& p, const Vec3& wi, const LightContext& ctx = {});
// The light's expected contribution at p with normal n (n = 0: no cosine), for light selection:
// mean intensity over distance^2, times a bound of the receiver's cosine over the sphere. Zero
// exactly when no point of the light is above p's tangent plane.
float importance(const PointLight& light, const Vec3& p, const Vec3& n);

}  // namespace toyrt
