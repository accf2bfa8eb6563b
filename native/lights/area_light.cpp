#include "lights/area_light.h"

#include "lights/light_matrix.h"
#include "lights/spherical_rectangle.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace toyrt {
namespace {

void require(bool ok, const char* message) {
  if (!ok) throw std::invalid_argument(std::string("area light: ") + message);
}

bool use_solid_angle(const AreaLight& light, AreaSampling sampling) {
  return sampling == AreaSampling::SolidAngle && light.is_rectangle();
}

// Density of area sampling over `area`, converted to solid angle.
float area_pdf(float area, float distance, float cos_light) { return distance * distance / (area * cos_light); }

// The part of the light that sample() draws from for shading point p at `height` over its plane:
// the whole light, or for a rectangle with a spread the part within spread.reach(height) of p's
// foot on the plane (f = 0 beyond it). evaluate() rebuilds the same region for its density.
struct Region {
  Vec3 center, edge_x, edge_y;
  float area;
  Vec3 corner() const { return center - 0.5f * edge_x - 0.5f * edge_y; }
};

// False when a spread leaves nothing of the light that reaches p.
bool sampled_region(const AreaLight& light, const Vec3& p, float height, Region& r) {
  r = {light.center, light.edge_x, light.edge_y, light.area};
  if (!light.spread.active || !light.is_rectangle()) return true;
  const float lx = glm::length(light.edge_x), ly = glm::length(light.edge_y);
  const Vec3 ux = light.edge_x / lx, uy = light.edge_y / ly;
  const Vec3 foot = p - height * light.normal - light.center;
  const float reach = light.spread.reach(height), cu = glm::dot(foot, ux), cv = glm::dot(foot, uy);
  const float u0 = std::max(cu - reach, -0.5f * lx), u1 = std::min(cu + reach, 0.5f * lx);
  const float v0 = std::max(cv - reach, -0.5f * ly), v1 = std::min(cv + reach, 0.5f * ly);
  if (!(u0 < u1 && v0 < v1)) return false;
  r = {light.center + 0.5f * (u0 + u1) * ux + 0.5f * (v0 + v1) * uy, (u1 - u0) * ux, (v1 - v0) * uy,
       (u1 - u0) * (v1 - v0)};
  return true;
}

}  // namespace

AreaLight AreaLight::make(AreaShape shape, float size, float size_y, const Mat4& m, float power, const Vec3& color,
                          float spread) {
  const bool square = shape == AreaShape::Square || shape == AreaShape::Disk;
  const float sx = size, sy = square ? size : size_y;
  require(std::isfinite(sx) && std::isfinite(sy) && sx > 0.0f && sy > 0.0f, "size must be positive and finite");
  require(std::isfinite(power) && power >= 0.0f, "power must be finite and >= 0 W");
  require(is_finite(color) && !glm::any(glm::lessThan(color, Vec3(0.0f))), "colour must be finite and >= 0");
  require(std::isfinite(spread) && spread > 0.0f, "spread must be a positive angle in radians (pi: no slats)");
  check_light_matrix(m, "area light");
  const Vec3 ax(m[0]), ay(m[1]), az(m[2]);
  const float lx = glm::length(ax), ly = glm::length(ay), lz = glm::length(az);
  require(lx > 0.0f && ly > 0.0f && lz > 0.0f, "matrix_world has a zero scale");
  constexpr float kShear = 1e-4f;  // cosine tolerance for float rotation matrices
  require(std::fabs(glm::dot(ax, ay)) <= kShear * lx * ly && std::fabs(glm::dot(ax, az)) <= kShear * lx * lz &&
              std::fabs(glm::dot(ay, az)) <= kShear * ly * lz,
          "matrix_world is sheared: the light would not be a rectangle");

  AreaLight light;
  light.shape = shape;
  light.center = Vec3(m[3]);
  light.edge_x = sx * ax;
  light.edge_y = sy * ay;
  light.normal = -az / lz;
  const float rect_area = (sx * lx) * (sy * ly);
  light.area = light.is_rectangle() ? rect_area : 0.25f * kPi * rect_area;
  light.radiance = power * color / (4.0f * light.area);
  light.spread = AreaSpread::make(spread);
  return light;
}

AreaLight AreaLight::from_params(const Params& params) {
  const Settings d;
  // Read one by one, so the first bad argument is the one reported, whatever the compiler's order.
  const Mat4 matrix = params.matrix("matrix", d.matrix);
  const AreaShape shape = parse_area_shape(params.text("shape", area_shape_name(d.shape)));
  const float size = float(params.positive("size", d.size));
  // Checked by make() where the shape uses it (the add-on sends Blender's size_y for any shape).
  const float size_y = float(params.number("size_y", size));
  const float power = float(params.non_negative("power", d.power));
  const Vec3 color = params.color("color", d.color);
  const float spread = float(params.positive("spread", d.spread));
  return make(shape, size, size_y, matrix, power, color, spread);
}

LightSample sample(const AreaLight& light, const Vec3& p, const Vec2& u, const LightContext& ctx) {
  LightSample s;
  const float height = glm::dot(p - light.center, light.normal);
  if (!(height > 0.0f)) return s;  // one-sided
  Region region;
  if (!sampled_region(light, p, height, region)) return s;
  float pdf = 0.0f;
  Vec3 q;
  bool by_area = true;
  if (use_solid_angle(light, ctx.area_sampling)) {
    const SphericalRectangle rect = SphericalRectangle::make(p, region.corner(), region.edge_x, region.edge_y);
    if (rect.solid_angle >= SphericalRectangle::kMinSolidAngle) {
      q = rect.sample(u);
      pdf = float(1.0 / rect.solid_angle);
      by_area = false;
    }
  }
  if (by_area) {
    const Vec2 local = light.is_rectangle() ? u - Vec2(0.5f) : 0.5f * sample_uniform_disk_concentric(u);
    q = region.center + local.x * region.edge_x + local.y * region.edge_y;
  }
  const Vec3 to_light = q - p;
  const float distance = glm::length(to_light);
  if (!(distance > 0.0f)) return s;
  const Vec3 wi = to_light / distance;
  const float cos_light = -glm::dot(wi, light.normal);
  if (!(cos_light > 0.0f)) return s;
  const float slats = light.spread.factor(wi, light.normal);
  if (!(slats > 0.0f)) return s;  // beyond the spread: no shadow ray for nothing
  s.point = q;
  s.wi = wi;
  s.distance = distance;
  s.radiance = light.radiance * slats;
  s.pdf = by_area ? area_pdf(region.area, distance, cos_light) : pdf;
  return s;
}

LightEval evaluate(const AreaLight& light, const Vec3& p, const Vec3& wi, const LightContext& ctx) {
  LightEval e;
  const float height = glm::dot(p - light.center, light.normal);
  const float cos_light = -glm::dot(wi, light.normal);
  if (!(height > 0.0f) || !(cos_light > 0.0f)) return e;
  const float t = height / cos_light;
  const Vec3 offset = p + t * wi - light.center;
  const float a = glm::dot(offset, light.edge_x) / glm::dot(light.edge_x, light.edge_x);
  const float b = glm::dot(offset, light.edge_y) / glm::dot(light.edge_y, light.edge_y);
  const bool inside = light.is_rectangle() ? std::fabs(a) <= 0.5f && std::fabs(b) <= 0.5f : a * a + b * b <= 0.25f;
  if (!inside) return e;
  const float slats = light.spread.factor(wi, light.normal);
  Region region;
  if (!(slats > 0.0f) || !sampled_region(light, p, height, region)) return e;
  e.radiance = light.radiance * slats;
  e.distance = t;
  e.pdf = area_pdf(region.area, t, cos_light);
  if (use_solid_angle(light, ctx.area_sampling)) {
    const double omega = SphericalRectangle::make(p, region.corner(), region.edge_x, region.edge_y).solid_angle;
    if (omega >= SphericalRectangle::kMinSolidAngle) e.pdf = float(1.0 / omega);
  }
  return e;
}

float importance(const AreaLight& light, const Vec3& p, const Vec3& n) {
  const Vec3 from_centre = p - light.center;
  const float height = glm::dot(from_centre, light.normal);
  if (!(height > 0.0f)) return 0.0f;
  const float d2 = glm::dot(from_centre, from_centre);
  const float d = std::sqrt(d2);
  const float r2 = 0.25f * (glm::dot(light.edge_x, light.edge_x) + glm::dot(light.edge_y, light.edge_y));
  // The bounding sphere (radius r, the half diagonal) subtends a cone of half-angle
  // asin(r / d) from p; a cosine measured from the centre can grow by that much.
  const float sin_b = std::min(1.0f, std::sqrt(r2) / d);
  const float cos_b = std::sqrt(std::max(0.0f, 1.0f - sin_b * sin_b));
  const auto widened = [&](float cos_theta) {
    if (cos_theta >= cos_b) return 1.0f;
    const float sin_theta = std::sqrt(std::max(0.0f, 1.0f - cos_theta * cos_theta));
    return cos_theta * cos_b + sin_theta * sin_b;
  };
  // p is in front of the plane, so every point of the light sees it at a positive cosine: keep
  // the bound positive even where rounding would make it 0.
  const float cos_emit = std::max(widened(height / d), 1e-6f);
  float cos_receive = 1.0f;
  if (n != Vec3(0.0f)) {
    cos_receive = widened(-glm::dot(n, from_centre) / (d * glm::length(n)));
    if (cos_receive <= 0.0f) return 0.0f;
  }
  const float mean_intensity = (light.radiance.x + light.radiance.y + light.radiance.z) / 3.0f * light.area;
  // The slats' f is largest at the smallest angle, whose cosine cos_emit bounds.
  return mean_intensity * light.spread.at_cos(cos_emit) * cos_emit * cos_receive / std::max(d2, r2);
}

LightBounds bounds(const AreaLight& light) {
  LightBounds b;
  const Vec3 c = light.corner();
  for (const Vec3& q : {c, c + light.edge_x, c + light.edge_y, c + light.edge_x + light.edge_y}) b.box.extend(q);
  b.axis = light.normal;
  b.theta_o = 0.0f;
  b.theta_e = light.spread.half_angle();
  b.power = (light.radiance.x + light.radiance.y + light.radiance.z) / 3.0f * light.area * light.spread.peak();
  return b;
}

AreaShape parse_area_shape(const std::string& name) {
  if (name == "RECTANGLE") return AreaShape::Rectangle;
  if (name == "SQUARE") return AreaShape::Square;
  if (name == "DISK") return AreaShape::Disk;
  if (name == "ELLIPSE") return AreaShape::Ellipse;
  throw std::invalid_argument("area light shape must be 'RECTANGLE', 'SQUARE', 'DISK' or 'ELLIPSE', got '" + name +
                              "'");
}

const char* area_shape_name(AreaShape shape) {
  switch (shape) {
    case AreaShape::Rectangle:
      return "RECTANGLE";
    case AreaShape::Square:
      return "SQUARE";
    case AreaShape::Disk:
      return "DISK";
    case AreaShape::Ellipse:
      return "ELLIPSE";
  }
  return "?";
}

AreaSampling parse_area_sampling(const std::string& name) {
  if (name == "solid_angle") return AreaSampling::SolidAngle;
  if (name == "area") return AreaSampling::Area;
  throw std::invalid_argument("area_light_sampling must be 'solid_angle' or 'area', got '" + name + "'");
}

const char* area_sampling_name(AreaSampling sampling) {
  return sampling == AreaSampling::SolidAngle ? "solid_angle" : "area";
}

}  // namespace toyrt
