// What a light tree (lights/light_tree.h) knows of one light: where its emitting points lie, the
// cone their emission directions fill, and a power comparable to importance() x distance^2, so
// that a cluster's bound and a single light's importance() weigh the same way (Conty Estevez and
// Kulla 2018, "Importance Sampling of Many Lights with Adaptive Tree Splitting", section 4).
// Each light type provides  LightBounds bounds(const X&)  beside its importance().
#pragma once

#include "core/bbox.h"
#include "sampling/warp.h"

namespace toyrt {

struct LightBounds {
  BBox box;  // every point that emits; empty for a light at infinity
  // The orientation cone: every emitting normal lies within theta_o of axis, and each emits
  // within theta_e around its normal. A point light: theta_o = pi (all normals), theta_e = pi/2.
  Vec3 axis{0.0f, 0.0f, 1.0f};
  float theta_o = kPi;
  float theta_e = 0.5f * kPi;
  // Mean intensity (W/sr) of a local light: importance() is about power / distance^2 at normal
  // incidence. For a light at infinity its irradiance (W/m^2), importance() without a distance.
  float power = 0.0f;
  bool distant = false;  // a sun: no position, chosen among its kind by importance()
};

}  // namespace toyrt
