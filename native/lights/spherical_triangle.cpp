#include "lights/spherical_triangle.h"

#include <algorithm>
#include <cmath>

namespace toyrt {
namespace {

constexpr double kPiD = 3.14159265358979323846;

// The angle at vertex x of the spherical triangle x y z: between the great circles to y and z,
// from their tangent directions at x.
double corner_angle(const DVec3& x, const DVec3& y, const DVec3& z) {
  const DVec3 ty = y - glm::dot(x, y) * x, tz = z - glm::dot(x, z) * x;
  return std::atan2(glm::length(glm::cross(ty, tz)), glm::dot(ty, tz));
}

// The unit vector in the plane of x and y, orthogonal to x, towards y (y not parallel to x).
DVec3 orthogonal_towards(const DVec3& x, const DVec3& y) {
  const DVec3 t = y - glm::dot(x, y) * x;
  const double len = glm::length(t);
  return len > 0.0 ? t / len : DVec3(0.0);
}

}  // namespace

SphericalTriangle SphericalTriangle::make(const Vec3& p, const Vec3& v0, const Vec3& v1, const Vec3& v2) {
  SphericalTriangle t;
  const DVec3 o(p);
  const DVec3 a = DVec3(v0) - o, b = DVec3(v1) - o, c = DVec3(v2) - o;
  const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
  if (!(la > 0.0 && lb > 0.0 && lc > 0.0)) return t;
  t.a = a / la;
  t.b = b / lb;
  t.c = c / lc;
  const double alpha = corner_angle(t.a, t.b, t.c), beta = corner_angle(t.b, t.c, t.a),
               gamma = corner_angle(t.c, t.a, t.b);
  const double omega = alpha + beta + gamma - kPiD;
  if (!(omega > 0.0) || !std::isfinite(omega)) return t;
  t.alpha = alpha;
  t.cos_c = glm::dot(t.a, t.b);
  t.solid_angle = omega;
  return t;
}

Vec3 SphericalTriangle::sample(const Vec2& u) const {
  // The sub-triangle A B C' of solid angle u0 Omega.
  const double area = double(u.x) * solid_angle;
  const double s = std::sin(area - alpha), t = std::cos(area - alpha);
  const double sa = std::sin(alpha), ca = std::cos(alpha);
  const double uu = t - ca, vv = s + sa * cos_c;
  const double den = (vv * s + uu * t) * sa;
  const double q = std::clamp(den != 0.0 ? ((vv * t - uu * s) * ca - vv) / den : 1.0, -1.0, 1.0);
  const DVec3 c1 = q * a + std::sqrt(std::max(0.0, 1.0 - q * q)) * orthogonal_towards(a, c);
  // The point on the arc B C' at cosine z to B.
  const double z = 1.0 - double(u.y) * (1.0 - glm::dot(c1, b));
  const DVec3 d = z * b + std::sqrt(std::max(0.0, 1.0 - z * z)) * orthogonal_towards(b, c1);
  return Vec3(glm::normalize(d));
}

}  // namespace toyrt
