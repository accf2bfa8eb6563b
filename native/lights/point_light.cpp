#include "lights/point_light.h"

#include "sampling/frame.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace toyrt {

PointLight PointLight::make(const Vec3& position, float power, const Vec3& color, float radius, bool soft_falloff) {
  if (!is_finite(position)) throw std::invalid_argument("point light: position is not finite");
  if (!std::isfinite(power) || power < 0.0f)
    throw std::invalid_argument("point light: power must be finite and >= 0 W");
  if (!is_finite(color) || glm::any(glm::lessThan(color, Vec3(0.0f))))
    throw std::invalid_argument("point light: colour must be finite and >= 0");
  if (!std::isfinite(radius) || radius < 0.0f)
    throw std::invalid_argument("point light: radius must be finite and >= 0 m");
  PointLight light;
  light.position = position;
  light.radius = radius;
  light.soft_falloff = soft_falloff;
  light.intensity = power * color / (4.0f * kPi);
  light.radiance = radius > 0.0f ? light.intensity / (kPi * radius * radius) : Vec3(0.0f);
  return light;
}

PointLight PointLight::from_params(const Params& params) {
  const Settings d;
  // Read one by one, so the first bad argument is the one reported, whatever the compiler's order.
  const Vec3 position = params.point("position", d.position);
  const float power = float(params.non_negative("power", d.power));
  const Vec3 color = params.color("color", d.color);
  const float radius = float(params.non_negative("radius", d.radius));
  const bool soft_falloff = params.flag("soft_falloff", d.soft_falloff);
  return make(position, power, color, radius, soft_falloff);
}

namespace {

// The sphere's cap seen from p, described without cancellation: 1 - cos(theta_max) from
// sin^2 / (1 + cos), which stays accurate for a small light far away.
float one_minus_cos_max(float distance2, float radius) {
  const float sin2 = std::min(1.0f, radius * radius / distance2);
  return sin2 / (1.0f + std::sqrt(1.0f - sin2));
}

// Distance along unit wi from p (outside) to the near side of the sphere, or from p (inside) to
// its far side; negative if the line misses. The squared distance of the centre from the line,
// not b^2 - c, keeps the discriminant accurate far from the light.
float sphere_distance(const PointLight& light, const Vec3& p, const Vec3& wi, bool inside) {
  const Vec3 to_centre = light.position - p;
  const float b = glm::dot(to_centre, wi);
  const Vec3 perpendicular = to_centre - b * wi;
  const float disc = light.radius * light.radius - glm::dot(perpendicular, perpendicular);
  if (disc < 0.0f) return -1.0f;
  return inside ? b + std::sqrt(disc) : b - std::sqrt(disc);
}

}  // namespace

LightSample sample(const PointLight& light, const Vec3& p, const Vec2& u, const LightContext&) {
  LightSample s;
  const Vec3 to_centre = light.position - p;
  const float d2 = glm::dot(to_centre, to_centre);
  if (light.radius == 0.0f) {
    if (!(d2 > 0.0f)) return s;
    s.distance = std::sqrt(d2);
    s.point = light.position;
    s.wi = to_centre / s.distance;
    s.radiance = light.intensity / d2;
    s.pdf = 1.0f;
    s.delta = true;
    return s;
  }
  if (light.soft_falloff) {
    // The disk through the centre facing p: a uniform point on it, its density in solid angle
    // t^2 / (pi R^2 cos_disk); cos_disk = d / t > 0 wherever p is not the centre itself.
    if (!(d2 > 0.0f)) return s;
    const float d = std::sqrt(d2);
    const Vec3 axis = -to_centre / d;  // the disk's normal, towards p
    const Vec2 q = light.radius * sample_uniform_disk_concentric(u);
    const Frame frame = Frame::from_normal(axis);
    s.point = light.position + frame.to_world(Vec3(q, 0.0f));
    const Vec3 to_point = s.point - p;
    s.distance = glm::length(to_point);
    if (!(s.distance > 0.0f)) return s;
    s.wi = to_point / s.distance;
    const float cos_disk = -glm::dot(axis, s.wi);
    if (!(cos_disk > 0.0f)) return s;
    s.pdf = s.distance * s.distance / (kPi * light.radius * light.radius * cos_disk);
    s.radiance = light.radiance;
    return s;
  }
  const bool inside = d2 <= light.radius * light.radius;
  if (inside) {
    // Radiance L arrives from every direction: sample them all.
    s.wi = sample_uniform_sphere(u);
    s.pdf = uniform_sphere_pdf();
    s.distance = std::max(0.0f, sphere_distance(light, p, s.wi, true));
  } else {
    const float omc = one_minus_cos_max(d2, light.radius);
    const float d = std::sqrt(d2);
    const Vec3 local = sample_uniform_cone(u, omc);
    s.wi = glm::normalize(Frame::from_normal(to_centre / d).to_world(local));
    s.pdf = uniform_cone_pdf(omc);
    // Rounding can put a direction on the cap's rim just outside the sphere: take the tangent point.
    const float t = sphere_distance(light, p, s.wi, false);
    s.distance = t > 0.0f ? t : glm::dot(to_centre, s.wi);
  }
  s.point = p + s.distance * s.wi;
  s.radiance = light.radiance;
  return s;
}

LightEval evaluate(const PointLight& light, const Vec3& p, const Vec3& wi, const LightContext&) {
  LightEval e;
  if (light.radius == 0.0f) return e;
  const Vec3 to_centre = light.position - p;
  const float d2 = glm::dot(to_centre, to_centre);
  if (light.soft_falloff) {
    // The disk facing p: the plane through the centre with normal towards p.
    if (!(d2 > 0.0f)) return e;
    const float d = std::sqrt(d2);
    const float cos_disk = glm::dot(to_centre, wi) / d;  // = -dot(disk normal, wi)
    if (!(cos_disk > 0.0f)) return e;
    const float t = d / cos_disk;
    const Vec3 off = p + t * wi - light.position;
    if (!(glm::dot(off, off) <= light.radius * light.radius)) return e;
    e.distance = t;
    e.radiance = light.radiance;
    e.pdf = t * t / (kPi * light.radius * light.radius * cos_disk);
    return e;
  }
  const bool inside = d2 <= light.radius * light.radius;
  const float t = sphere_distance(light, p, wi, inside);
  if (t < 0.0f || (!inside && glm::dot(to_centre, wi) <= 0.0f)) return e;
  e.distance = t;
  e.radiance = light.radiance;
  e.pdf = inside ? uniform_sphere_pdf() : uniform_cone_pdf(one_minus_cos_max(d2, light.radius));
  return e;
}

float importance(const PointLight& light, const Vec3& p, const Vec3& n) {
  const Vec3 to_centre = light.position - p;
  const float d2 = glm::dot(to_centre, to_centre);
  const float r2 = light.radius * light.radius;
  const float mean_intensity = (light.intensity.x + light.intensity.y + light.intensity.z) / 3.0f;
  float cos_bound = 1.0f;
  if (n != Vec3(0.0f) && d2 > r2) {
    // The receiver's cosine is at most cos(max(0, theta - theta_max)), theta the angle between n
    // and the centre, theta_max the cone's half-angle: zero only when the whole sphere is below
    // the tangent plane.
    const float d = std::sqrt(d2);
    const float cos_theta = glm::dot(n, to_centre) / (d * glm::length(n));
    const float sin_max = light.radius / d;
    const float cos_max = std::sqrt(std::max(0.0f, 1.0f - sin_max * sin_max));
    const float sin_theta = std::sqrt(std::max(0.0f, 1.0f - cos_theta * cos_theta));
    if (cos_theta < cos_max)  // theta > theta_max
      cos_bound = cos_theta * cos_max + sin_theta * sin_max;
    if (cos_bound <= 0.0f) return 0.0f;
  }
  return mean_intensity * cos_bound / std::max({d2, r2, 1e-12f});
}

LightBounds bounds(const PointLight& light) {
  LightBounds b;
  b.box.extend(light.position - Vec3(light.radius));
  b.box.extend(light.position + Vec3(light.radius));
  b.power = (light.intensity.x + light.intensity.y + light.intensity.z) / 3.0f;
  return b;
}

}  // namespace toyrt
