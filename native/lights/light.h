// The closed set of lights, dispatched statically: a std::variant and one std::visit per call
// (a jump on the index, no virtual call, no allocation). How area lights are sampled is the
// render's choice (AreaSampling), passed along; point lights have one sampler.
#pragma once

#include "core/overloaded.h"
#include "lights/area_light.h"
#include "lights/point_light.h"

#include <variant>

namespace toyrt {

using Light = std::variant<PointLight, AreaLight>;

inline LightSample sample_light(const Light& light, const Vec3& p, const Vec2& u, AreaSampling area) {
  return std::visit(Overloaded{[&](const PointLight& l) { return sample(l, p, u); },
                               [&](const AreaLight& l) { return sample(l, p, u, area); }},
                    light);
}
inline LightEval evaluate_light(const Light& light, const Vec3& p, const Vec3& wi, AreaSampling area) {
  return std::visit(Overloaded{[&](const PointLight& l) { return evaluate(l, p, wi); },
                               [&](const AreaLight& l) { return evaluate(l, p, wi, area); }},
                    light);
}
inline float light_importance(const Light& light, const Vec3& p, const Vec3& n) {
  return std::visit([&](const auto& l) { return importance(l, p, n); }, light);
}

}  // namespace toyrt
