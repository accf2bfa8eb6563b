// An orthonormal frame around a unit vector: local directions (z along the normal) to world and
// back. Built branch-free and without a singularity (Duff et al. 2017, "Building an Orthonormal
// Basis, Revisited", JCGT 6(1)).
#pragma once

#include "core/math.h"

#include <cmath>

namespace toyrt {

struct Frame {
  Vec3 t, b, n;  // tangent, bitangent, normal: right-handed, t x b = n

  static Frame from_normal(const Vec3& n) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float c = n.x * n.y * a;
    return {Vec3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x), Vec3(c, sign + n.y * n.y * a, -n.y), n};
  }
  Vec3 to_world(const Vec3& v) const { return v.x * t + v.y * b + v.z * n; }
  Vec3 to_local(const Vec3& v) const { return Vec3(glm::dot(v, t), glm::dot(v, b), glm::dot(v, n)); }
};

}  // namespace toyrt
