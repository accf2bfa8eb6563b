// The render's choices a light's sampler reads, passed to every sample() and evaluate() so one
// scene renders with any of them without being copied: the light types' uniform signatures
//     sample(const X&, const Vec3& p, const Vec2& u, const LightContext&)
//     evaluate(const X&, const Vec3& p, const Vec3& wi, const LightContext&)
// take it whether or not the type uses it. A new choice is a member here (and a render setting).
#pragma once

namespace toyrt {

// Area lights: uniform over the light's area (density dist^2 / (area cos) in solid angle), or
// uniform over the solid angle of the spherical rectangle (Urena et al. 2013; rectangles and
// squares only).
enum class AreaSampling { Area, SolidAngle };

struct LightContext {
  AreaSampling area_sampling = AreaSampling::SolidAngle;

  LightContext() = default;
  // Implicit: callers that only choose the area estimator pass it as is.
  LightContext(AreaSampling area) : area_sampling(area) {}  // NOLINT(google-explicit-constructor)
};

}  // namespace toyrt
