// A ray and the record of its nearest hit, in the conventions of the Python API (and Embree's):
// the hit point is org + t * dir, and p = (1 - u - v) * p0 + u * p1 + v * p2 on triangle `prim`.
#pragma once

#include "core/math.h"

namespace toyrt {

struct Ray {
  Vec3 org;
  float tnear = 0.0f;
  Vec3 dir;
  float tfar = kInfinity;  // shrinks to the nearest hit found so far during traversal
};

inline constexpr int32_t kInvalidId = -1;

struct Hit {
  float t = kInfinity;  // stays infinite on a miss
  float u = 0.0f, v = 0.0f;
  int32_t prim = kInvalidId;      // triangle index within its mesh
  int32_t instance = kInvalidId;  // instance index within the scene
  bool found() const { return prim != kInvalidId; }
};

}  // namespace toyrt
