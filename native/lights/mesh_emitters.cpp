#include "lights/mesh_emitters.h"

#include "geometry/offset_ray.h"
#include "lights/spherical_triangle.h"

#include <algorithm>
#include <cmath>

namespace toyrt {
namespace {

float mean(const Vec3& c) { return (c.x + c.y + c.z) / 3.0f; }

// Which side of t p is on (Front: the side its normal points to), 0 in its plane.
uint8_t side_of(const EmissiveTriangle& t, float height) {
  return height > 0.0f ? uint8_t(EmitterSides::Front) : height < 0.0f ? uint8_t(EmitterSides::Back) : 0;
}

}  // namespace

float importance(const EmissiveTriangle& t, const Vec3& p, const Vec3& n) {
  const float height = glm::dot(p - t.p0, t.normal);
  const uint8_t side = side_of(t, height);
  if (!(uint8_t(t.sides) & side)) return 0.0f;
  const Vec3 vertices[3] = {t.p0, t.p0 + t.e1, t.p0 + t.e2};
  LightTreeNode node;
  node.lo = glm::min(vertices[0], glm::min(vertices[1], vertices[2]));
  node.hi = glm::max(vertices[0], glm::max(vertices[1], vertices[2]));
  node.axis = height > 0.0f ? t.normal : -t.normal;  // the side p sees: theta_o = 0
  node.cos_o = 1.0f;
  node.sin_o = 0.0f;
  node.cos_e = 0.0f;  // theta_e = pi / 2: a Lambertian emitter
  node.power = t.area * mean(t.radiance);
  return cluster_importance(node, p, n, vertices, 3);
}

LightBounds bounds(const EmissiveTriangle& t) {
  LightBounds b;
  b.box.extend(t.p0);
  b.box.extend(t.p0 + t.e1);
  b.box.extend(t.p0 + t.e2);
  b.power = t.area * mean(t.radiance);
  b.theta_e = 0.5f * kPi;
  if (t.sides == EmitterSides::Front || t.sides == EmitterSides::Back) {
    b.axis = t.sides == EmitterSides::Front ? t.normal : -t.normal;
    b.theta_o = 0.0f;
  } else {
    b.axis = glm::normalize(t.e1);  // both normals lie pi / 2 from any direction in the plane
    b.theta_o = 0.5f * kPi;
  }
  return b;
}

void MeshEmitters::add(const EmissiveTriangle& t, uint64_t key) {
  if (!(t.area > 0.0f) || !std::isfinite(t.area) || !(mean(t.radiance) > 0.0f)) return;
  keys.push_back(key == UINT64_MAX ? uint64_t(triangles.size()) : key);
  triangles.push_back(t);
}

int64_t MeshEmitters::index_of(uint64_t key) const {
  const auto it = std::lower_bound(keys.begin(), keys.end(), key);
  return it != keys.end() && *it == key ? int64_t(it - keys.begin()) : -1;
}

size_t MeshEmitters::memory_bytes() const {
  return triangles.capacity() * sizeof(EmissiveTriangle) + keys.capacity() * sizeof(uint64_t) +
         cdf.capacity() * sizeof(float) + tree.memory_bytes();
}

void MeshEmitters::finish(size_t tree_from, uint32_t leaf_size, float min_diagonal) {
  double run = 0.0;
  for (const EmissiveTriangle& t : triangles) run += double(t.area) * mean(t.radiance);
  total_power = run;
  tree = LightTree{};
  cdf.clear();
  if (!triangles.empty() && triangles.size() >= tree_from) {
    std::vector<LightBounds> all;
    all.reserve(triangles.size());
    BBox box;
    for (const EmissiveTriangle& t : triangles) {
      all.push_back(bounds(t));
      box.extend(all.back().box);
    }
    // One compact emitter keeps the CDF (kEmitterTreeSpread).
    if (!(glm::length(box.extent()) < min_diagonal)) {
      tree = LightTree(all, leaf_size);
      return;
    }
  }
  cdf.assign(triangles.size() + 1, 0.0f);
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

// The barycentrics (along e1, e2) of a point in t's plane: the solid-angle sampler finds the
// point, not its coordinates.
Vec2 barycentrics(const EmissiveTriangle& t, const Vec3& point) {
  const Vec3 d = point - t.p0;
  const float a = glm::dot(t.e1, t.e1), b = glm::dot(t.e1, t.e2), c = glm::dot(t.e2, t.e2);
  const float x = glm::dot(d, t.e1), y = glm::dot(d, t.e2);
  const float det = a * c - b * b;
  if (!(det > 0.0f)) return Vec2(1.0f / 3.0f);
  const Vec2 r((c * x - b * y) / det, (a * y - b * x) / det);
  return glm::clamp(r, Vec2(0.0f), Vec2(1.0f));
}

}  // namespace

float emitter_probability(const MeshEmitters& emitters, const Vec3& p, const Vec3& n, size_t index) {
  if (index >= emitters.triangles.size() || emitters.total_power <= 0.0) return 0.0f;
  if (emitters.uses_tree()) return emitters.tree.probability(emitters.triangles.data(), p, n, index);
  const EmissiveTriangle& t = emitters.triangles[index];
  return float(double(t.area) * mean(t.radiance) / emitters.total_power);
}

float emitter_pdf(const MeshEmitters& emitters, const Vec3& p, const Vec3& n, size_t index, const Vec3& wi,
                  float distance) {
  if (index >= emitters.triangles.size()) return 0.0f;
  const EmissiveTriangle& t = emitters.triangles[index];
  const float height = glm::dot(p - t.p0, t.normal);
  if (!(uint8_t(t.sides) & side_of(t, height))) return 0.0f;
  const float chosen = emitter_probability(emitters, p, n, index);
  if (!(chosen > 0.0f)) return 0.0f;
  if (close_to(t, height)) {
    const SphericalTriangle st = SphericalTriangle::make(p, t.p0, t.p0 + t.e1, t.p0 + t.e2);
    if (st.solid_angle > SphericalTriangle::kMinSolidAngle) return chosen / float(st.solid_angle);
  }
  const float cos_light = std::fabs(glm::dot(t.normal, wi));
  return cos_light > 0.0f ? chosen * distance * distance / (t.area * cos_light) : 0.0f;
}

LightSample sample_emitters(const MeshEmitters& emitters, const Vec3& p, const Vec3& normal, const Vec2& u,
                            EmitterPoint* where) {
  LightSample s;
  const size_t n = emitters.triangles.size();
  if (n == 0) return s;
  size_t i = 0;
  float width = 0.0f, ux = 0.0f;  // the probability of triangle i; u.x rescaled within it for the point
  if (emitters.uses_tree()) {
    const LightSelection pick = emitters.tree.select(emitters.triangles.data(), p, normal, u.x);
    if (!pick.found()) return s;
    i = size_t(pick.index);
    width = pick.probability;
    ux = pick.remainder;
  } else {
    // The triangle: cdf[i] <= u.x < cdf[i + 1].
    const auto it = std::upper_bound(emitters.cdf.begin() + 1, emitters.cdf.end(), u.x);
    i = std::min(size_t(it - emitters.cdf.begin()) - 1, n - 1);
    const float lo = emitters.cdf[i];
    width = emitters.cdf[i + 1] - lo;
    if (!(width > 0.0f)) return s;
    ux = std::clamp((u.x - lo) / width, 0.0f, 0.99999994f);
  }
  const EmissiveTriangle& t = emitters.triangles[i];
  // Which side p sees, from its height over the triangle's plane.
  const float height = glm::dot(p - t.p0, t.normal);
  if (!(uint8_t(t.sides) & side_of(t, height))) return s;
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
      if (where != nullptr) *where = EmitterPoint{i, t.textured ? barycentrics(t, s.point) : Vec2(0.0f)};
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
  if (where != nullptr) *where = EmitterPoint{i, b};
  // The shadow ray ends at `point`: moved off the triangle towards p, so the emitter's own
  // surface (at t = 1 up to rounding) cannot block it.
  s.point = offset_ray_origin(s.point, cos_light > 0.0f ? t.normal : -t.normal);
  return s;
}

}  // namespace toyrt
