#include "lights/spot_light.h"

#include "lights/light_matrix.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace toyrt {
namespace {

float smoothstep(float x) {
  if (x <= 0.0f) return 0.0f;
  if (x >= 1.0f) return 1.0f;
  return x * x * (3.0f - 2.0f * x);
}

// The factor at cosine c with edge cos_half over width `blend` (0: a hard edge, which must not
// divide 0 by 0 exactly on the edge).
float edge(float c, float cos_half, float blend) {
  if (blend <= 0.0f) return c > cos_half ? 1.0f : 0.0f;
  return smoothstep((c - cos_half) / blend);
}

// The widest world angle between the cone's axis and a direction attenuation() lets through. 3.x
// tests the world cosine: the half angle. 4.x tests the cosine in the (scaled) object frame, so the
// world cone is elliptical: its edge is mapped back to world directions at 256 points, and the
// largest angle between neighbours is added to the widest one found, which bounds the edge between
// the points (a bound for importance(), not the exact cone).
float widest_cone_angle(const SpotLight& light, float half) {
  if (half >= 0.5f * kPi) return kPi;  // a hemisphere or more: no useful bound
  if (light.falloff == SpotFalloff::CosineSmoothstep) return half;
  const glm::mat3 to_world = glm::inverse(light.to_local);
  constexpr int kEdge = 256;
  float widest = 0.0f, step = 0.0f;
  Vec3 previous{0.0f};
  for (int k = 0; k <= kEdge; ++k) {
    const float phi = 2.0f * kPi * float(k) / kEdge;
    const Vec3 local(std::sin(half) * std::cos(phi), std::sin(half) * std::sin(phi), std::cos(half));
    const Vec3 w = glm::normalize(to_world * local);
    widest = std::max(widest, std::acos(std::clamp(glm::dot(w, light.direction), -1.0f, 1.0f)));
    if (k > 0) step = std::max(step, std::acos(std::clamp(glm::dot(w, previous), -1.0f, 1.0f)));
    previous = w;
  }
  return std::min(widest + step, kPi);
}
}  // namespace

SpotLight SpotLight::make(const Settings& s) {
  const Mat4& m = s.matrix;
  check_light_matrix(m, "spot light");
  const glm::mat3 linear(m);
  const float det = glm::determinant(linear);
  if (!std::isfinite(det) || det == 0.0f) throw std::invalid_argument("spot light: matrix has a zero scale");
  if (!(s.spot_size > 0.0f && s.spot_size <= kPi))
    throw std::invalid_argument("spot light: spot_size must be in (0, pi] radians");
  if (!(s.spot_blend >= 0.0f && s.spot_blend <= 1.0f))
    throw std::invalid_argument("spot light: spot_blend must be in [0, 1]");
  SpotLight light;
  light.emitter = PointLight::make(Vec3(m[3]), s.power, s.color, s.radius, s.soft_falloff);
  // Local +Z along the cone (the object's -Z), so the cosine is the local z of v.
  light.to_local = glm::mat3(1, 0, 0, 0, 1, 0, 0, 0, -1) * glm::inverse(linear);
  light.direction = glm::normalize(-Vec3(m[2]));
  light.cos_half = std::cos(0.5f * s.spot_size);
  light.blend_width = (1.0f - light.cos_half) * s.spot_blend;
  light.falloff = s.falloff;
  light.outer_angle = widest_cone_angle(light, 0.5f * s.spot_size);
  return light;
}

SpotLight SpotLight::from_params(const Params& params) {
  Settings s;
  s.matrix = params.matrix("matrix", s.matrix);
  s.power = float(params.non_negative("power", s.power));
  s.color = params.color("color", s.color);
  s.radius = float(params.non_negative("radius", s.radius));
  s.soft_falloff = params.flag("soft_falloff", s.soft_falloff);
  s.spot_size = float(params.number("spot_size", s.spot_size));
  s.spot_blend = float(params.number("spot_blend", s.spot_blend));
  s.falloff = parse_spot_falloff(params.text("falloff", spot_falloff_name(s.falloff)));
  return make(s);
}

float SpotLight::attenuation(const Vec3& v) const {
  if (falloff == SpotFalloff::CosineSmoothstep) {
    const float c = glm::dot(direction, v);
    if (c <= cos_half) return 0.0f;
    return c * edge(c, cos_half, blend_width);
  }
  const Vec3 local = to_local * v;
  const float len = glm::length(local);
  if (!(len > 0.0f)) return 0.0f;
  return edge(local.z / len, cos_half, blend_width);
}

namespace {

// Whether the shading point is inside the emitter's sphere, where Cycles 4.x does not attenuate.
bool inside_sphere(const SpotLight& light, const Vec3& p) {
  const PointLight& e = light.emitter;
  if (e.soft_falloff || e.radius == 0.0f) return false;
  const Vec3 d = p - e.position;
  return glm::dot(d, d) <= e.radius * e.radius;
}

}  // namespace

LightSample sample(const SpotLight& light, const Vec3& p, const Vec2& u, const LightContext& ctx) {
  LightSample s = sample(light.emitter, p, u, ctx);
  if (!s.valid() || inside_sphere(light, p)) return s;
  const float a = light.attenuation(-s.wi);
  if (a <= 0.0f) return LightSample{};
  s.radiance *= a;
  return s;
}

LightEval evaluate(const SpotLight& light, const Vec3& p, const Vec3& wi, const LightContext& ctx) {
  LightEval e = evaluate(light.emitter, p, wi, ctx);
  if (!e.hit() || inside_sphere(light, p)) return e;
  e.radiance *= light.attenuation(-wi);
  return e;
}

float importance(const SpotLight& light, const Vec3& p, const Vec3& n) {
  const float base = importance(light.emitter, p, n);
  if (base <= 0.0f) return base;
  const Vec3 v = p - light.emitter.position;
  const float len = glm::length(v);
  if (light.emitter.radius == 0.0f) return len > 0.0f ? base * light.attenuation(v / len) : 0.0f;
  // A round spot: its disk's points see p within asin(radius / len) of the centre's direction, so
  // p is lit only if that cap reaches inside the cone (outside it, the old importance had every
  // point beside a spot pick it, for nothing: bench sun_spot with one light per hit). Inside the
  // sphere (4.x without soft falloff) nothing is attenuated.
  if (!(len > light.emitter.radius) || inside_sphere(light, p)) return base;
  const float centre = std::acos(std::clamp(glm::dot(v / len, light.direction), -1.0f, 1.0f));
  const float cap = std::asin(std::min(1.0f, light.emitter.radius / len));
  return centre - cap > light.outer_angle ? 0.0f : base;
}

// The point light's box and power, with the cone: every emitting direction within outer_angle of
// the axis (theta_o = 0, theta_e = outer_angle). A round spot's disk lights p when a direction
// from one of its points to p lies in the cone, and those points are in the box, whose theta_u
// covers them: so a cluster's bound is zero only where importance() is.
LightBounds bounds(const SpotLight& light) {
  LightBounds b = bounds(light.emitter);
  if (light.outer_angle >= kPi) return b;  // no useful cone: a point light's bounds
  b.axis = light.direction;
  b.theta_o = 0.0f;
  b.theta_e = light.outer_angle;
  return b;
}

SpotFalloff parse_spot_falloff(const std::string& name) {
  if (name == "SMOOTHSTEP") return SpotFalloff::Smoothstep;
  if (name == "COSINE_SMOOTHSTEP") return SpotFalloff::CosineSmoothstep;
  throw std::invalid_argument("spot light falloff must be 'SMOOTHSTEP' or 'COSINE_SMOOTHSTEP', got '" + name + "'");
}

const char* spot_falloff_name(SpotFalloff falloff) {
  return falloff == SpotFalloff::Smoothstep ? "SMOOTHSTEP" : "COSINE_SMOOTHSTEP";
}

}  // namespace toyrt
