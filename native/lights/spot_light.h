// Blender's spot light: a point light (its power, colour, radius and soft falloff, lights/
// point_light.h) whose light is limited to a cone around the object's local -Z. Blender gives
// a spot of power P the intensity P / (4 pi) inside the cone, like a point light: narrowing the
// cone does not concentrate the light.
//
// The cone's edge, in Cycles' two versions (the attenuation multiplies the point light's
// radiance along each direction v from the light's sampled point towards the shading point):
// - falloff 'SMOOTHSTEP' (Cycles 4.0+): v in the object's local frame (its inverse matrix, so a
//   non-uniformly scaled spot has an elliptic cone), z its cosine to -Z; the attenuation is
//   smoothstep((z - cos(spot_size / 2)) / ((1 - cos(spot_size / 2)) spot_blend)). Inside a
//   sphere light (soft falloff off, shading point within the radius) there is none.
// - falloff 'COSINE_SMOOTHSTEP' (Cycles 3.x): c the cosine of v to the light's direction (the
//   object's scale does not matter); zero outside the cone, otherwise c, times
//   smoothstep((c - cos(spot_size / 2)) / ((1 - cos(spot_size / 2)) spot_blend)) within the
//   blend: the cosine dims even the cone's axis region towards its edge.
// smoothstep(x) = 3x^2 - 2x^3 on [0, 1], 0 below, 1 above; spot_blend 0 is a hard edge.
//
// Parameters (add_light('SPOT', ...), Blender's names): matrix ((4, 4) world matrix, identity;
// points along local -Z), power (W, 10), color ((1, 1, 1)), radius (m, 0), soft_falloff (True),
// spot_size (full cone angle, rad, 45 degrees), spot_blend (0.15), falloff ('SMOOTHSTEP').
#pragma once

#include "core/params.h"
#include "lights/light_context.h"
#include "lights/light_sample.h"
#include "lights/point_light.h"

#include <string>

namespace toyrt {

enum class SpotFalloff { Smoothstep, CosineSmoothstep };

struct SpotLight {
  static constexpr const char* kType = "SPOT";  // Blender's light type
  static constexpr const char* kParams =
      "matrix ((4, 4) world matrix, identity; points along local -Z), power (W, 10), color (linear RGB,\n"
      "    (1, 1, 1)), radius (m, 0), soft_falloff (True), spot_size (full cone angle, rad, 0.785398),\n"
      "    spot_blend (0..1, 0.15), falloff ('SMOOTHSTEP': Cycles 4.0+; 'COSINE_SMOOTHSTEP': Cycles 3.x)";

  // Blender's settings, with the defaults of a new spot light.
  struct Settings {
    Mat4 matrix{1.0f};
    float power = 10.0f;  // W
    Vec3 color{1.0f};
    float radius = 0.0f;  // m
    bool soft_falloff = true;
    float spot_size = 0.785398163f;  // rad, the cone's full angle
    float spot_blend = 0.15f;
    SpotFalloff falloff = SpotFalloff::Smoothstep;
  };

  PointLight emitter;           // at the object's location
  glm::mat3 to_local{1.0f};     // world directions into the object's frame, local +Z along the cone
  Vec3 direction{0, 0, -1.0f};  // unit, the cone's axis in world space (Cycles 3.x's test)
  float cos_half = 0.0f;        // cos(spot_size / 2)
  float blend_width = 0.0f;     // (1 - cos_half) spot_blend: the cosine range of the soft edge
  SpotFalloff falloff = SpotFalloff::Smoothstep;
  // The widest angle from `direction` at which attenuation() can be positive: the half spot
  // angle, or with 4.x's non-uniform scale the widest of its elliptical cone (for importance()).
  float outer_angle = kPi;

  // Throws std::invalid_argument for a bad matrix (non-finite, non-affine, singular), spot_size
  // outside (0, pi], spot_blend outside [0, 1], or the point light's own errors.
  static SpotLight make(const Settings& settings);
  static SpotLight from_params(const Params& params);

  // The cone's factor for unit direction v from the light towards the shading point.
  float attenuation(const Vec3& v) const;
};

LightSample sample(const SpotLight& light, const Vec3& p, const Vec2& u, const LightContext& ctx);
LightEval evaluate(const SpotLight& light, const Vec3& p, const Vec3& wi, const LightContext& ctx);
// The point light's importance, times the cone's factor towards p (a delta spot) or 1 (a round
// one, whose cone edge is blurred by its size: a bound, never zero where light can arrive).
float importance(const SpotLight& light, const Vec3& p, const Vec3& n);
// The emitter's bounds: the point light's box and power, and the cone of directions
// attenuation() lets through (outer_angle around the axis, the elliptical cone's widest angle).
LightBounds bounds(const SpotLight& light);

SpotFalloff parse_spot_falloff(const std::string& name);  // throws std::invalid_argument
const char* spot_falloff_name(SpotFalloff falloff);

}  // namespace toyrt
