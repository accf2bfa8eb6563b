// Blender's sun light: light from infinitely far away along the object's local -Z, strength S in
// W/m^2 (times the colour): the irradiance of a surface facing it. `angle` is the full angular
// diameter of the sun's disc; 0 is a delta direction (hard shadows), which gives exactly
// E = S cos(theta).
//
// A disc of angle 2h > 0 has two forms, Cycles' two versions (both give a facing surface about S):
// - disc 'CONE' (Cycles 4.0+): uniform radiance L = S / (pi sin^2 h) over the cone of half-angle
//   h, sampled uniformly by solid angle; a facing surface receives pi L sin^2 h = S exactly.
// - disc 'TANGENT_DISK' (Cycles 3.x): directions through a uniform point of the disk of radius
//   tan h one unit away, radiance S / (pi tan^2 h cos^3) along a direction at angle theta to the
//   axis (so each sample gives S cos_receiver); a facing surface receives a little less than S
//   (0.9999 at Blender's default 0.526 degrees).
// Camera and specular rays that leave the scene within the disc see it, as in Cycles.
//
// Parameters (add_light('SUN', ...), Blender's names): matrix ((4, 4) world matrix, identity;
// shines along local -Z), strength (W/m^2, 1; Blender's energy), color ((1, 1, 1)), angle (rad,
// Blender's default 0.00918), disc ('CONE').
#pragma once

#include "core/params.h"
#include "lights/light_bounds.h"
#include "lights/light_context.h"
#include "lights/light_sample.h"
#include "sampling/warp.h"

#include <string>

namespace toyrt {

enum class SunDisc { Cone, TangentDisk };

struct SunLight {
  static constexpr const char* kType = "SUN";  // Blender's light type
  static constexpr const char* kParams =
      "matrix ((4, 4) world matrix, identity; shines along local -Z), strength (W/m^2, 1), color (linear RGB,\n"
      "    (1, 1, 1)), angle (full angular diameter, rad, 0.00918; 0: hard shadows), disc ('CONE': Cycles 4.0+;\n"
      "    'TANGENT_DISK': Cycles 3.x)";

  struct Settings {
    Mat4 matrix{1.0f};
    float strength = 1.0f;  // W/m^2
    Vec3 color{1.0f};
    float angle = 0.00918043f;  // rad: Blender's default, 0.526 degrees
    SunDisc disc = SunDisc::Cone;
  };

  Vec3 to_sun{0, 0, 1.0f};  // unit, from the scene towards the sun (the object's +Z)
  Vec3 irradiance{1.0f};    // S colour, W/m^2
  float cos_half = 1.0f;    // cos(angle / 2); 1: a delta direction
  float one_minus_cos = 0.0f;
  float tan_half = 0.0f;
  SunDisc disc = SunDisc::Cone;

  bool is_delta() const { return one_minus_cos == 0.0f; }

  // Throws std::invalid_argument for a bad matrix (non-finite, non-affine, zero Z axis), a
  // negative strength or colour, or an angle outside [0, pi).
  static SunLight make(const Settings& settings);
  static SunLight from_params(const Params& params);
};

// A direction towards the disc; distance is infinite (the shadow ray is unbounded).
LightSample sample(const SunLight& light, const Vec3& p, const Vec2& u, const LightContext& ctx);
// The disc along wi (nothing for angle 0), at distance FLT_MAX: behind anything a ray can hit.
LightEval evaluate(const SunLight& light, const Vec3& p, const Vec3& wi, const LightContext& ctx);
// S times a bound of the receiver's cosine over the disc (no distance: the sun is as bright everywhere).
float importance(const SunLight& light, const Vec3& p, const Vec3& n);
// A light at infinity (distant), its mean irradiance as power.
LightBounds bounds(const SunLight& light);

SunDisc parse_sun_disc(const std::string& name);  // throws std::invalid_argument
const char* sun_disc_name(SunDisc disc);

}  // namespace toyrt
