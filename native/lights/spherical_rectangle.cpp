#include "lights/spherical_rectangle.h"

#include <algorithm>
#include <cmath>

namespace toyrt {
namespace {

constexpr double kTwoPi = 6.283185307179586476925;

// Interior angle of the spherical polygon between two consecutive edge planes.
double interior_angle(const DVec3& a, const DVec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), -glm::dot(a, b));
}

}  // namespace

SphericalRectangle SphericalRectangle::make(const Vec3& p, const Vec3& corner, const Vec3& edge_x, const Vec3& edge_y) {
  SphericalRectangle r;
  const DVec3 ex(edge_x), ey(edge_y);
  const double length_x = glm::length(ex), length_y = glm::length(ey);
  r.origin = DVec3(p);
  r.x = ex / length_x;
  r.y = ey / length_y;
  r.z = glm::cross(r.x, r.y);
  const DVec3 d = DVec3(corner) - r.origin;
  r.x0 = glm::dot(d, r.x);
  r.y0 = glm::dot(d, r.y);
  r.z0 = glm::dot(d, r.z);
  if (r.z0 > 0.0) {  // the construction wants the rectangle below p
    r.z0 = -r.z0;
    r.z = -r.z;
  }
  r.x1 = r.x0 + length_x;
  r.y1 = r.y0 + length_y;
  if (!(r.z0 < 0.0)) return r;  // p in the plane: nothing to see

  const DVec3 v00(r.x0, r.y0, r.z0), v01(r.x0, r.y1, r.z0), v10(r.x1, r.y0, r.z0), v11(r.x1, r.y1, r.z0);
  const DVec3 n0 = glm::normalize(glm::cross(v00, v10));
  const DVec3 n1 = glm::normalize(glm::cross(v10, v11));
  const DVec3 n2 = glm::normalize(glm::cross(v11, v01));
  const DVec3 n3 = glm::normalize(glm::cross(v01, v00));
  const double g0 = interior_angle(n0, n1), g1 = interior_angle(n1, n2);
  const double g2 = interior_angle(n2, n3), g3 = interior_angle(n3, n0);
  r.b0 = n0.z;
  r.b1 = n2.z;
  r.k = kTwoPi - g2 - g3;
  r.solid_angle = std::max(0.0, g0 + g1 + g2 + g3 - kTwoPi);
  return r;
}

Vec3 SphericalRectangle::sample(const Vec2& u) const {
  // x: the sub-rectangle [x0, xu] holding a fraction u.x of the solid angle.
  const double phi = double(u.x) * solid_angle + k;
  const double f = (b0 * std::cos(phi) - b1) / std::sin(phi);
  double c = std::copysign(1.0, f) / std::sqrt(f * f + b0 * b0);  // f = +-inf gives c = 0, as it should
  if (!std::isfinite(c)) c = 0.0;
  c = std::clamp(c, -1.0, 1.0);
  const double xu = std::clamp(-c * z0 / std::sqrt(std::max(1.0 - c * c, 1e-300)), x0, x1);
  // y: uniform in h = y / sqrt(d^2 + y^2) along the line x = xu.
  const double d = std::sqrt(xu * xu + z0 * z0);
  const double h0 = y0 / std::sqrt(d * d + y0 * y0), h1 = y1 / std::sqrt(d * d + y1 * y1);
  const double h = h0 + double(u.y) * (h1 - h0);
  const double yv = std::clamp(h * h < 1.0 ? h * d / std::sqrt(1.0 - h * h) : y1, y0, y1);
  return Vec3(origin + xu * x + yv * y + z0 * z);
}

}  // namespace toyrt
