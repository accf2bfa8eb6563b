// The closed set of lights, dispatched statically: a std::variant and one std::visit per call
// (a jump on the index, no virtual call, no allocation).
#pragma once

#include "lights/area_light.h"
#include "lights/point_light.h"

#include <variant>

namespace toyrt {

using Light = std::variant<PointLight, AreaLight>;

inline LightSample sample_light(const Light& light, const Vec3& p, const Vec2& u) {
  return std::visit([&](const auto& l) { return sample(l, p, u); }, light);
}
inline LightEval evaluate_light(const Light& light, const Vec3& p, const Vec3& wi) {
  return std::visit([&](const auto& l) { return evaluate(l, p, wi); }, light);
}
inline float light_importance(const Light& light, const Vec3& p, const Vec3& n) {
  return std::visit([&](const auto& l) { return importance(l, p, n); }, light);
}

}  // namespace toyrt
