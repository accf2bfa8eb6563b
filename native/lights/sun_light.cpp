#include "lights/sun_light.h"

#include "lights/light_matrix.h"
#include "sampling/frame.h"
#include "sampling/warp.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace toyrt {

SunLight SunLight::make(const Settings& s) {
  check_light_matrix(s.matrix, "sun light");
  const Vec3 z(s.matrix[2]);
  const float len = glm::length(z);
  if (!(len > 0.0f)) throw std::invalid_argument("sun light: matrix_world has a zero scale");
  if (!std::isfinite(s.strength) || s.strength < 0.0f)
    throw std::invalid_argument("sun light: strength must be finite and >= 0 W/m^2");
  if (!is_finite(s.color) || glm::any(glm::lessThan(s.color, Vec3(0.0f))))
    throw std::invalid_argument("sun light: colour must be finite and >= 0");
  if (!(s.angle >= 0.0f && s.angle < kPi)) throw std::invalid_argument("sun light: angle must be in [0, pi) radians");
  SunLight light;
  light.to_sun = z / len;
  light.irradiance = s.strength * s.color;
  const float half = 0.5f * s.angle;
  light.cos_half = std::cos(half);
  // 1 - cos h = 2 sin^2(h / 2), accurate for the tiny discs suns have.
  const float sin_quarter = std::sin(0.5f * half);
  light.one_minus_cos = 2.0f * sin_quarter * sin_quarter;
  light.tan_half = std::tan(half);
  light.disc = s.disc;
  return light;
}

SunLight SunLight::from_params(const Params& params) {
  Settings s;
  s.matrix = params.matrix("matrix", s.matrix);
  s.strength = float(params.non_negative("strength", s.strength));
  s.color = params.color("color", s.color);
  s.angle = float(params.non_negative("angle", s.angle));
  s.disc = parse_sun_disc(params.text("disc", sun_disc_name(s.disc)));
  return make(s);
}

namespace {

// The radiance along a direction at cosine c to the axis, and the sampler's density there.
void disc_radiance(const SunLight& light, float c, Vec3& radiance, float& pdf) {
  if (light.disc == SunDisc::Cone) {
    pdf = uniform_cone_pdf(light.one_minus_cos);
    // L = S / (pi sin^2 h); sin^2 h = (1 - cos h)(1 + cos h).
    radiance = light.irradiance / (kPi * light.one_minus_cos * (1.0f + light.cos_half));
    return;
  }
  pdf = c * c * c / (kPi * light.tan_half * light.tan_half);
  radiance = light.irradiance * pdf;
}

}  // namespace

LightSample sample(const SunLight& light, const Vec3& p, const Vec2& u, const LightContext&) {
  LightSample s;
  s.distance = kInfinity;
  if (light.is_delta()) {
    s.wi = light.to_sun;
    s.radiance = light.irradiance;  // a delta direction: irradiance at normal incidence, pdf 1
    s.pdf = 1.0f;
    s.delta = true;
  } else {
    const Frame frame = Frame::from_normal(light.to_sun);
    if (light.disc == SunDisc::Cone) {
      s.wi = glm::normalize(frame.to_world(sample_uniform_cone(u, light.one_minus_cos)));
    } else {
      const Vec2 q = light.tan_half * sample_uniform_disk_concentric(u);
      s.wi = glm::normalize(frame.to_world(Vec3(q, 1.0f)));
    }
    disc_radiance(light, glm::dot(s.wi, light.to_sun), s.radiance, s.pdf);
  }
  s.point = p + s.wi;  // a direction: only wi and the infinite distance matter
  return s;
}

LightEval evaluate(const SunLight& light, const Vec3&, const Vec3& wi, const LightContext&) {
  LightEval e;
  if (light.is_delta()) return e;
  const float c = glm::dot(wi, light.to_sun);
  if (!(c >= light.cos_half)) return e;
  e.distance = std::numeric_limits<float>::max();
  disc_radiance(light, c, e.radiance, e.pdf);
  return e;
}

float importance(const SunLight& light, const Vec3&, const Vec3& n) {
  const float mean = (light.irradiance.x + light.irradiance.y + light.irradiance.z) / 3.0f;
  if (n == Vec3(0.0f)) return mean;
  // The receiver's cosine is at most cos(max(0, theta - h)) over the disc.
  const float cos_theta = glm::dot(n, light.to_sun) / glm::length(n);
  const float sin_theta = std::sqrt(std::max(0.0f, 1.0f - cos_theta * cos_theta));
  const float sin_half = std::sqrt(std::max(0.0f, 1.0f - light.cos_half * light.cos_half));
  const float bound = cos_theta >= light.cos_half ? 1.0f : cos_theta * light.cos_half + sin_theta * sin_half;
  return bound > 0.0f ? mean * bound : 0.0f;
}

LightBounds bounds(const SunLight& light) {
  LightBounds b;
  b.axis = -light.to_sun;
  b.power = (light.irradiance.x + light.irradiance.y + light.irradiance.z) / 3.0f;
  b.distant = true;
  return b;
}

SunDisc parse_sun_disc(const std::string& name) {
  if (name == "CONE") return SunDisc::Cone;
  if (name == "TANGENT_DISK") return SunDisc::TangentDisk;
  throw std::invalid_argument("sun light disc must be 'CONE' or 'TANGENT_DISK', got '" + name + "'");
}

const char* sun_disc_name(SunDisc disc) { return disc == SunDisc::Cone ? "CONE" : "TANGENT_DISK"; }

}  // namespace toyrt
