// Blender's point light in Cycles' units: power P in watts, times the colour per channel, radiated
// evenly in all directions, so the radiant intensity is I = P colour / (4 pi) W/sr and a surface
// at distance r facing it at angle theta receives E = I cos(theta) / r^2 (BLENDER_UNITS.md:
// 100 W at 1 m gives a white Lambert pixel of I / pi = 2.533).
//
// Radius 0 is a delta light (hard shadows). Radius R > 0 has uniform radiance L over one of two
// shapes, both with projected area pi R^2 from the shading point, so equal power gives the same
//     L = I / (pi R^2) = P colour / (4 pi^2 R^2)
// for both (Cycles' eval_fac of 1 / (4 pi R^2 pi) per watt):
// - soft falloff (Blender's use_soft_falloff, its default, and Cycles 3.x's only model): a disk of
//   radius R through the centre, facing the shading point, sampled uniformly by area; each sample
//   gives I cos_disk / t^2, so the irradiance below the light is I / (d^2 + R^2) on its axis (not
//   I / d^2): it stays finite as the point approaches the light, and a 1 m light 1 m above a
//   surface gives half of what a sphere gives there.
// - sphere (use_soft_falloff off, Cycles 4.0+): a true sphere, sampled uniformly by solid angle
//   over the cone it subtends (over all directions from inside). Where the whole sphere lies
//   above the receiver's tangent plane its irradiance is pi L sin^2(theta_max) cos(theta) =
//   I cos(theta) / r^2 exactly, the point light's.
// The two differ by about R^2 / d^2 and agree far from the light.
//
// Parameters (add_light('POINT', ...), Blender's names): position ((0, 0, 0), m), power (10 W),
// color ((1, 1, 1), linear RGB), radius (0 m: shadow_soft_size; 0 is a delta light, hard
// shadows), soft_falloff (True: the disk; False: the sphere): PointLight::Settings.
#pragma once

#include "core/params.h"
#include "lights/light_bounds.h"
#include "lights/light_context.h"
#include "lights/light_sample.h"
#include "sampling/warp.h"

namespace toyrt {

struct PointLight {
  static constexpr const char* kType = "POINT";  // Blender's light type
  static constexpr const char* kParams =
      "position (m, (0, 0, 0)), power (W, 10), color (linear RGB, (1, 1, 1)), radius (m, 0: hard shadows),\n"
      "    soft_falloff (True: a disk facing the shading point, as Cycles 3.x and Blender's default; False: a sphere)";

  // Blender's settings, with the defaults of a new point light (radius 0: hard shadows).
  struct Settings {
    Vec3 position{0.0f};  // m
    float power = 10.0f;  // W
    Vec3 color{1.0f};     // linear RGB
    float radius = 0.0f;  // m
    bool soft_falloff = true;
  };

  Vec3 position{0.0f};
  float radius = 0.0f;       // m; 0: a delta light
  Vec3 intensity{0.0f};      // I = P colour / (4 pi), W/sr
  Vec3 radiance{0.0f};       // of the disk's or sphere's surface, I / (pi R^2); 0 when radius is 0
  bool soft_falloff = true;  // the disk facing the shading point; false: the sphere

  // Blender's settings: location, power (W), colour (linear RGB), radius (shadow_soft_size, m).
  // soft_falloff: the disk (true) or the sphere. Throws std::invalid_argument for non-finite
  // values, negative power, colour or radius.
  static PointLight make(const Vec3& position, float power, const Vec3& color, float radius = 0.0f,
                         bool soft_falloff = true);
  // From Params named as Settings' members.
  static PointLight from_params(const Params& params);
};

// A direction towards the light from shading point p (u: two uniform numbers, used for R > 0).
LightSample sample(const PointLight& light, const Vec3& p, const Vec2& u, const LightContext& ctx = {});
// The disk or sphere along direction wi from p (nothing for radius 0: a delta light cannot be hit).
LightEval evaluate(const PointLight& light, const Vec3& p, const Vec3& wi, const LightContext& ctx = {});
// The light's expected contribution at p with normal n (n = 0: no cosine), for light selection:
// mean intensity over distance^2, times a bound of the receiver's cosine over the sphere. Zero
// exactly when no point of the light is above p's tangent plane.
float importance(const PointLight& light, const Vec3& p, const Vec3& n);
// The sphere's box, emitting every way (theta_o = pi), with the mean intensity as power.
LightBounds bounds(const PointLight& light);

}  // namespace toyrt
