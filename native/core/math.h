// Vector maths for the core: GLM types under short names, plus the floating-point error bounds
// that the watertight triangle test and the conservative box test rely on.
#pragma once

#include <glm/glm.hpp>

#include <cmath>
#include <cstdint>
#include <limits>

namespace toyrt {

using Vec3 = glm::vec3;
using DVec3 = glm::dvec3;
using Mat4 = glm::mat4;

inline constexpr float kInfinity = std::numeric_limits<float>::infinity();

// gamma(n) = n * eps / (1 - n * eps): the relative error bound of n chained float operations
// (pbrt's notation, eps = 2^-24 is half an ulp at 1). Used to widen box tests conservatively.
inline constexpr float gamma(int n) {
  constexpr float eps = std::numeric_limits<float>::epsilon() * 0.5f;
  return (n * eps) / (1 - n * eps);
}

// Max and min that ignore a NaN second argument: with them, a slab test whose 0 * inf product
// is NaN (origin on a slab plane, direction parallel to it) keeps the other bound instead of
// poisoning the interval.
inline float safe_max(float value, float candidate) { return candidate > value ? candidate : value; }
inline float safe_min(float value, float candidate) { return candidate < value ? candidate : value; }

inline int max_dimension(const Vec3& v) { return v.x > v.y ? (v.x > v.z ? 0 : 2) : (v.y > v.z ? 1 : 2); }

inline bool is_finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

}  // namespace toyrt
