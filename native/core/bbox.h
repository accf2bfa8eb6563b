// Axis-aligned bounding box, and the ray-box slab test used by every BVH traversal.
#pragma once

#include "core/math.h"

#include <algorithm>

namespace toyrt {

struct BBox {
  Vec3 lo{kInfinity};
  Vec3 hi{-kInfinity};

  void extend(const Vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void extend(const BBox& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  // Halved before the sum, so boxes near +-FLT_MAX have a finite centre (halving is exact).
  Vec3 center() const { return 0.5f * lo + 0.5f * hi; }
  Vec3 extent() const { return hi - lo; }
  // Half the surface area: SAH costs only ever compare areas, so the factor 2 is dropped.
  float half_area() const {
    if (empty()) return 0.0f;
    Vec3 e = extent();
    return e.x * e.y + e.y * e.z + e.z * e.x;
  }
  bool contains(const BBox& b) const {
    return b.lo.x >= lo.x && b.lo.y >= lo.y && b.lo.z >= lo.z && b.hi.x <= hi.x && b.hi.y <= hi.y && b.hi.z <= hi.z;
  }
};

// Per-ray data precomputed once for all box tests of a traversal.
struct RayBoxData {
  Vec3 org;
  Vec3 inv_dir;  // 1/dir; +-inf where a component is +-0 (IEEE division keeps the sign of zero)
  int near[3];   // index of the near plane per axis in a {lo.x, lo.y, lo.z, hi.x, hi.y, hi.z} array
  int far[3];    // index of the far plane: near[a] +- 3
  // intersect_box's origins for the near and far planes: org moved by the pad towards or away
  // from the planes, which tests every box as if grown by the pad on all sides ((lo - pad - o) /
  // d = (lo - (o + pad)) / d). Equal to org without a pad.
  Vec3 near_org, far_org;
};

// pad >= 0 grows every box intersect_box tests by that much (the top level's instance boxes:
// scene/instance_bounds.h); the wide walks ignore it.
inline RayBoxData make_ray_box_data(const Vec3& org, const Vec3& dir, float pad = 0.0f) {
  RayBoxData r;
  r.org = org;
  r.inv_dir = Vec3(1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z);
  for (int a = 0; a < 3; ++a) {
    const bool negative = std::signbit(r.inv_dir[a]);
    r.near[a] = negative ? a + 3 : a;
    r.far[a] = negative ? a : a + 3;
    r.near_org[a] = negative ? org[a] - pad : org[a] + pad;
    r.far_org[a] = negative ? org[a] + pad : org[a] - pad;
  }
  return r;
}

// Slab test against bounds stored as {lo.x, lo.y, lo.z, hi.x, hi.y, hi.z}. The near and far
// planes are chosen by the ray's direction signs, so no min/max between the two slab distances
// is needed, and that is also what makes it NaN-safe: a 0 * inf = NaN can only come from a ray
// parallel to an axis whose origin lies exactly on a plane, and then the NaN is dropped by
// safe_max (near) or safe_min (far), which treats the ray as inside that slab, as it is.
// Conservative: the far distance is scaled by 1 + 2 gamma(3) so that rounding never makes a box
// miss a ray the watertight triangle test would hit inside it (Ize 2013, "Robust BVH Ray
// Traversal"). Ize's bound assumes distances >= 0; rays may start at a negative tnear, so a
// negative exit is scaled by 1 - 2 gamma(3) and a negative entry by 1 + 2 gamma(3): both move
// outwards by at least the rounding error of either (the fuzzer found a box missed at t = -1).
// With tnear >= 0 this is exactly Ize's test. Returns the entry distance, or +inf when the box is
// missed within [tnear, tfar].
inline float intersect_box(const RayBoxData& r, const float* bounds, float tnear, float tfar) {
  float tmin = tnear, tmax = kInfinity;
  for (int a = 0; a < 3; ++a) {
    tmin = safe_max(tmin, (bounds[r.near[a]] - r.near_org[a]) * r.inv_dir[a]);
    tmax = safe_min(tmax, (bounds[r.far[a]] - r.far_org[a]) * r.inv_dir[a]);
  }
  if (tmin < 0.0f) tmin *= 1.0f + 2.0f * gamma(3);
  tmax = std::min(tmax * (tmax < 0.0f ? 1.0f - 2.0f * gamma(3) : 1.0f + 2.0f * gamma(3)), tfar);
  return tmin <= tmax ? tmin : kInfinity;
}

}  // namespace toyrt
