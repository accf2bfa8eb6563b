// An area light's `spread` (Blender's name): the angle of the beam a soft box's grid of slats lets
// through. Cycles models it by the fraction of the light the slats do not hide at angle theta from
// the light's normal, linear in tan(theta) and zero from theta = spread / 2 on:
//     f(theta) = max(tan(h) - tan(theta), 0) / (tan(h) - h),   h = spread / 2,
// which multiplies the light's radiance. The divisor makes the emitted power that of the plain
// light: the integral of cos(theta) f(theta) over the hemisphere is pi, as that of f = 1
// (tests/native/area_spread_test.cpp integrates it). Blender 3.x and 4.x/5.x write the same
// function in two forms (3.x as (1 - tan(theta) / tan(h)) normalised by tan(h) / (tan(h) - h)).
//
// The light's points that reach a shading point at height t over its plane lie within t tan(h) of
// the point's foot on the plane: sampling only the part of a rectangle inside that square spends no
// samples on points whose f is 0 (a narrow spread makes a large soft box a small spot).
#pragma once

#include "core/math.h"
#include "sampling/warp.h"

#include <algorithm>
#include <cmath>

namespace toyrt {

struct AreaSpread {
  // 180 degrees (Blender's default) or more: no slats, f = 1 everywhere, and nothing is computed.
  bool active = false;
  float tan_half = 0.0f;   // tan(h)
  float normalize = 1.0f;  // 1 / (tan(h) - h)

  // spread in radians, > 0 (Cycles 3.x renders at least 1 degree; the add-on clamps per version).
  static AreaSpread make(float spread) {
    AreaSpread s;
    if (!(spread < kPi)) return s;
    const double h = 0.5 * double(spread);
    s.active = true;
    s.tan_half = float(std::tan(h));
    // tan(h) - h loses its digits for small h in float; its series h^3 / 3 (+ 2 h^5 / 15) does not.
    s.normalize = float(h > 0.05 ? 1.0 / (std::tan(h) - h) : 1.0 / (h * h * h / 3.0 + 2.0 * std::pow(h, 5) / 15.0));
    return s;
  }

  // f at the angle whose tangent is tan_theta (>= 0).
  float at_tan(float tan_theta) const { return active ? std::max(tan_half - tan_theta, 0.0f) * normalize : 1.0f; }
  // f along unit direction wi arriving at the light of unit normal n (wi . n < 0: its emitting
  // side). The sine comes from the cross product: from the cosine, small angles lose their digits
  // in float (a 1 degree beam would be off by 0.03 %).
  float factor(const Vec3& wi, const Vec3& n) const {
    if (!active) return 1.0f;
    return at_tan(glm::length(glm::cross(wi, n)) / -glm::dot(wi, n));
  }
  // f at the angle whose cosine is cos_theta (> 0), in double: a bound from cosines (importance()).
  float at_cos(double cos_theta) const {
    return active ? at_tan(float(std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta)) / cos_theta)) : 1.0f;
  }
  // f along the normal: the largest it gets.
  float peak() const { return active ? tan_half * normalize : 1.0f; }
  // The half angle h of the beam (pi / 2 when inactive): the light tree's emission cone.
  float half_angle() const { return active ? std::atan(tan_half) : 0.5f * kPi; }
  // Radius around a shading point's foot on the light's plane beyond which f = 0, at height t.
  float reach(float height) const { return height * tan_half; }
};

}  // namespace toyrt
