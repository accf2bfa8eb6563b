// A ray and the record of its nearest hit, in the conventions of the Python API (and Embree's):
// the hit point is org + t * dir, and p = (1 - u - v) * p0 + u * p1 + v * p2 on triangle `prim`.
#pragma once

#include "core/math.h"

namespace toyrt {

inline constexpr int32_t kInvalidId = -1;

// One triangle of one instance (named apart from the SAH builder's PrimRef, its primitive record).
struct TriangleRef {
  int32_t prim = kInvalidId;
  int32_t instance = kInvalidId;
};

struct Ray {
  Ray() = default;
  // A constructor, not aggregate initialisation: -Wextra warns at every Ray{org, tnear, dir, tfar}
  // that leaves `self` to its default, which is what most rays want.
  Ray(const Vec3& o, float near, const Vec3& d, float far, TriangleRef leaves = {})
      : org(o), tnear(near), dir(d), tfar(far), self(leaves) {}

  Vec3 org;
  float tnear = 0.0f;
  Vec3 dir;
  float tfar = kInfinity;  // shrinks to the nearest hit found so far during traversal
  // The triangle the ray leaves, never reported as its hit (Cycles' ray `self`). For a ray that
  // starts on a triangle and leaves it on the side its origin was moved to (offset_ray_origin), the
  // line meets that triangle's plane only behind the origin, so the exact test rejects it anyway,
  // but only after working out that the crossing is behind the start within rounding: the most
  // expensive step of a block test, reached on nearly every such ray (docs/trace-speed.md,
  // thirty-second session). Where the offset does not clear the triangle after all (an instance's
  // transform rounding the plane, a grazing direction rounded back below it), naming it removes that
  // self-hit, as in Cycles. Not for a ray meant to go back through the triangle it starts on,
  // which really crosses it.
  TriangleRef self;
};

struct Hit {
  float t = kInfinity;  // stays infinite on a miss
  float u = 0.0f, v = 0.0f;
  int32_t prim = kInvalidId;      // triangle index within its mesh
  int32_t instance = kInvalidId;  // instance index within the scene
  bool found() const { return prim != kInvalidId; }
};

}  // namespace toyrt
