// Warps from the unit square [0, 1)^2 to the domains that light transport samples, each with its
// density. Every warp is a measure-preserving map (up to the stated constant density) written
// from its derivation, so a stratified or low-discrepancy input stays well spread on the domain.
#pragma once

#include "core/math.h"

#include <algorithm>
#include <cmath>

namespace toyrt {

// core/math.h has the 3D types only; redeclaring this alias there later is harmless.
using Vec2 = glm::vec2;

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInvPi = 0.318309886183790671538f;

// Unit disk, density 1/pi. Shirley and Chiu's concentric map (1997, "A Low Distortion Map Between
// Disk and Square"): concentric squares go to concentric circles, so neighbouring samples stay
// neighbours and strata keep their shape, unlike the polar map (r = sqrt(u0), phi = 2 pi u1).
inline Vec2 sample_uniform_disk_concentric(const Vec2& u) {
  const float a = 2.0f * u.x - 1.0f, b = 2.0f * u.y - 1.0f;
  if (a == 0.0f && b == 0.0f) return Vec2(0.0f);
  float r, phi;
  if (std::fabs(a) > std::fabs(b)) {
    r = a;
    phi = (kPi / 4.0f) * (b / a);
  } else {
    r = b;
    phi = kPi / 2.0f - (kPi / 4.0f) * (a / b);
  }
  return r * Vec2(std::cos(phi), std::sin(phi));
}
inline float uniform_disk_pdf() { return kInvPi; }

// Hemisphere around +z with density cos(theta) / pi (Malley's method: a uniform disk point
// lifted onto the hemisphere; projected solid angle is the disk's area).
inline Vec3 sample_cosine_hemisphere(const Vec2& u) {
  const Vec2 d = sample_uniform_disk_concentric(u);
  const float z = std::sqrt(std::max(0.0f, 1.0f - d.x * d.x - d.y * d.y));
  return Vec3(d.x, d.y, z);
}
inline float cosine_hemisphere_pdf(float cos_theta) { return std::max(cos_theta, 0.0f) * kInvPi; }

// Unit sphere, density 1 / (4 pi): z uniform in [-1, 1] (Archimedes: equal heights cut equal
// areas), phi uniform.
inline Vec3 sample_uniform_sphere(const Vec2& u) {
  const float z = 1.0f - 2.0f * u.x;
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = 2.0f * kPi * u.y;
  return Vec3(r * std::cos(phi), r * std::sin(phi), z);
}
inline float uniform_sphere_pdf() { return 0.25f * kInvPi; }

// Uniform on a triangle: barycentrics (b1, b2) with p = (1 - b1 - b2) p0 + b1 p1 + b2 p2, the
// convention of the ray API's (u, v); density 1 / area. With b1 = 1 - s fixed, the points form a
// segment parallel to p0p2 whose length grows as s (its distance from p1), so the area within s
// of p1 grows as s^2 and s = sqrt(u0) inverts it; u1 places the point uniformly on the segment.
inline Vec2 sample_uniform_triangle(const Vec2& u) {
  const float s = std::sqrt(u.x);
  return Vec2(1.0f - s, u.y * s);
}

// Uniform on the regular polygon with `corners` >= 3 corners inscribed in the unit circle, its
// corners at angles rotation + (2k + 1) pi / corners, so with rotation 0 an edge's midpoint lies
// on +x (Blender's aperture blades). Density 1 / area, area = corners sin(2 pi / corners) / 2. The
// polygon is a fan of congruent triangles around the centre: u.x picks triangle k = floor(u.x n),
// equally likely since they have equal areas, and its fraction is reused (still uniform on [0, 1)
// given k), so the map keeps u's stratification within each triangle.
inline Vec2 sample_uniform_regular_polygon(const Vec2& u, int corners, float rotation) {
  const float n = float(corners);
  const float scaled = u.x * n;
  const float k = std::min(std::floor(scaled), n - 1.0f);
  const Vec2 b = sample_uniform_triangle(Vec2(scaled - k, u.y));
  // The triangle (centre, corner k, corner k + 1), barycentrics b of the two corners.
  const float a0 = rotation + (2.0f * k - 1.0f) * kPi / n, a1 = a0 + 2.0f * kPi / n;
  return b.x * Vec2(std::cos(a0), std::sin(a0)) + b.y * Vec2(std::cos(a1), std::sin(a1));
}
inline float regular_polygon_area(int corners) { return 0.5f * float(corners) * std::sin(2.0f * kPi / float(corners)); }

// Directions in the cone of half-angle theta_max around +z, density 1 / (2 pi (1 - cos theta_max)).
// The cone is given by one_minus_cos_max = 1 - cos(theta_max), which callers compute without
// cancellation (sin^2 / (1 + cos)); a small light far away has a cap of 1e-10 that
// 1 - cos(theta) in float would round to 0. cos(theta) is uniform in [cos theta_max, 1].
inline Vec3 sample_uniform_cone(const Vec2& u, float one_minus_cos_max) {
  const float one_minus_cos = u.x * one_minus_cos_max;
  const float cos_theta = 1.0f - one_minus_cos;
  const float sin_theta = std::sqrt(std::max(0.0f, one_minus_cos * (2.0f - one_minus_cos)));
  const float phi = 2.0f * kPi * u.y;
  return Vec3(sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta);
}
inline float uniform_cone_pdf(float one_minus_cos_max) { return 1.0f / (2.0f * kPi * one_minus_cos_max); }

}  // namespace toyrt
