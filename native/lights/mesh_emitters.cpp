#include "lights/mesh_emitters.h"

#include "geometry/offset_ray.h"
#include "lights/spherical_triangle.h"

#include <algorithm>
#include <cmath>

namespace toyrt {
namespace {

float mean(const Vec3& c) { return (c.x + c.y + c.z) / 3.0f; }

}  // namespace

void MeshEmitters::add(const EmissiveTriangle& t) {
  if (!(t.area > 0.0f) || !std::isfinite(t.area) || !(mean(t.radiance) > 0.0f)) return;
  triangles.push_back(t);
}

void MeshEmitters::finish() {
  cdf.assign(triangles.size() + 1, 0.0f);
  double run = 0.0;
  for (const EmissiveTriangle& t : triangles) run += double(t.area) * mean(t.radiance);
  total_power = run;
  double acc = 0.0;
  for (size_t i = 0; i < triangles.size(); ++i) {
    acc += double(triangles[i].area) * mean(triangles[i].radiance);
    cdf[i + 1] = float(acc / run);
  }
  if (!cdf.empty()) cdf.back() = 1.0f;
}

namespace {

// Cycles' rule for sampling a triangle by its solid angle: p is close to it, its longest edge
// longer than p's distance from its plane.
bool close_to(const EmissiveTriangle& t, float height) {
  const Vec3 e3 = t.e2 - t.e1;
  const float longest2 = std::max({glm::dot(t.e1, t.e1), glm::dot(t.e2, t.e2), glm::dot(e3, e3)});
  return longest2 > height * height;
}

}  // namespace

float emitter_pdf(const MeshEmitters& emitters, const Vec3& p, const EmissiveTriangle& t, const Vec3& wi,
                  float distance) {
  if (emitters.total_power <= 0.0 || !(t.area > 0.0f)) return 0.0f;
  const float height = glm::dot(p - t.p0, t.normal);
  const uint8_t side = height > 0.0f ? uint8_t(EmitterSides::Front) : uint8_t(EmitterSides::Back);
  if (height == 0.0f || !(uint8_t(t.sides) & side)) return 0.0f;
  const float chosen = float(double(t.area) * mean(t.radiance) / emitters.total_power);
  if (close_to(t, height)) {
    const SphericalTriangle st = SphericalTriangle::make(p, t.p0, t.p0 + t.e1, t.p0 + t.e2);
    if (st.solid_angle > SphericalTriangle::kMinSolidAngle) return chosen / float(st.solid_angle);
  }
  const float cos_light = std::fabs(glm::dot(t.normal, wi));
  return cos_light > 0.0f ? chosen * distance * distance / (t.area * cos_light) : 0.0f;
}

LightSample sample_emitters(const MeshEmitters& emitters, const Vec3& p, const Vec2& u) {
  LightSample s;
  const size_t n = emitters.triangles.size();
  if (n == 0) return s;
  // The triangle: cdf[i] <= u.x < cdf[i + 1]; u.x rescaled within it for the point.
  const auto it = std::upper_bound(emitters.cdf.begin() + 1, emitters.cdf.end(), u.x);
  const size_t i = std::min(size_t(it - emitters.cdf.begin()) - 1, n - 1);
  const float lo = emitters.cdf[i], width = emitters.cdf[i + 1] - lo;
  if (!(width > 0.0f)) return s;
  const float ux = std::clamp((u.x - lo) / width, 0.0f, 0.99999994f);
  const EmissiveTriangle& t = emitters.triangles[i];
  // Which side p sees, from its height over the triangle's plane.
  const float height = glm::dot(p - t.p0, t.normal);
  const uint8_t side = height > 0.0f ? uint8_t(EmitterSides::Front) : uint8_t(EmitterSides::Back);
  if (height == 0.0f || !(uint8_t(t.sides) & side)) return s;
  // Close to a triangle its solid angle is sampled; far away its area, where the two agree.
  if (close_to(t, height)) {
    const SphericalTriangle st = SphericalTriangle::make(p, t.p0, t.p0 + t.e1, t.p0 + t.e2);
    if (st.solid_angle > SphericalTriangle::kMinSolidAngle) {
      s.wi = st.sample(Vec2(ux, u.y));
      const float cos_light = -glm::dot(t.normal, s.wi);
      if (!(std::fabs(cos_light) > 0.0f) || (cos_light > 0.0f) != (height > 0.0f)) return s;
      s.distance = std::fabs(height) / std::fabs(cos_light);
      s.point = p + s.distance * s.wi;
      s.pdf = width / float(st.solid_angle);
      s.radiance = t.radiance;
      s.point = offset_ray_origin(s.point, cos_light > 0.0f ? t.normal : -t.normal);
      return s;
    }
  }
  const Vec2 b = sample_uniform_triangle(Vec2(ux, u.y));
  s.point = t.p0 + b.x * t.e1 + b.y * t.e2;
  const Vec3 to_point = s.point - p;
  const float d2 = glm::dot(to_point, to_point);
  if (!(d2 > 0.0f)) return s;
  s.distance = std::sqrt(d2);
  s.wi = to_point / s.distance;
  const float cos_light = -glm::dot(t.normal, s.wi);  // > 0: p sees the front
  if (cos_light == 0.0f || (cos_light > 0.0f) != (height > 0.0f)) return s;
  s.pdf = width * d2 / (t.area * std::fabs(cos_light));
  s.radiance = t.radiance;
  // The shadow ray ends at `point`: moved off the triangle towards p, so the emitter's own
  // surface (at t = 1 up to rounding) cannot block it.
  s.point = offset_ray_origin(s.point, cos_light > 0.0f ? t.normal : -t.normal);
  return s;
}

}  // namespace toyrt
