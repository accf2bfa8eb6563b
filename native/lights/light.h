// The closed set of lights, dispatched statically: a std::variant and one std::visit per call
// (a jump on the index, no virtual call, no allocation). The variant is the one table of light
// types: a new type is its own lights/<x>_light.{h,cpp} and one entry below. Each type provides
//     static constexpr const char* kType, kParams;  static X from_params(const Params&);  (make_light)
//     LightSample sample(const X&, const Vec3& p, const Vec2& u, const LightContext&);
//     LightEval evaluate(const X&, const Vec3& p, const Vec3& wi, const LightContext&);
//     float importance(const X&, const Vec3& p, const Vec3& n);  LightBounds bounds(const X&);  (light trees)
// and a type without them fails to compile here. The render's choices (how area lights are
// sampled) come in the LightContext.
#pragma once

#include "core/type_table.h"
#include "lights/area_light.h"
#include "lights/point_light.h"
#include "lights/spot_light.h"
#include "lights/sun_light.h"

#include <string>
#include <string_view>
#include <variant>

namespace toyrt {

using Light = std::variant<PointLight, AreaLight, SpotLight, SunLight>;

inline LightSample sample_light(const Light& light, const Vec3& p, const Vec2& u, const LightContext& ctx) {
  return std::visit([&](const auto& l) { return sample(l, p, u, ctx); }, light);
}
inline LightEval evaluate_light(const Light& light, const Vec3& p, const Vec3& wi, const LightContext& ctx) {
  return std::visit([&](const auto& l) { return evaluate(l, p, wi, ctx); }, light);
}
inline float light_importance(const Light& light, const Vec3& p, const Vec3& n) {
  return std::visit([&](const auto& l) { return importance(l, p, n); }, light);
}
inline LightBounds light_bounds(const Light& light) {
  return std::visit([](const auto& l) { return bounds(l); }, light);
}

// The light of Blender type `type` ("POINT", "AREA", "SPOT", "SUN": the kTypes) from its parameters. Throws
// std::invalid_argument for an unknown type (listing the known ones), a bad value or an argument
// the type does not read.
inline Light make_light(std::string_view type, const Params& params) {
  return make_from_params<Light>(type, params, "light");
}

}  // namespace toyrt
