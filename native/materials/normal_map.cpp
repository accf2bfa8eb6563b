#include "materials/normal_map.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <string>
#include <utility>

namespace toyrt {
namespace {

// v / |v|, or zero for a zero or non-finite vector (the callers' fallback cue).
Vec3 unit_or_zero(const Vec3& v) {
  const float len2 = glm::dot(v, v);
  if (!(len2 > 0.0f) || !std::isfinite(len2)) return Vec3(0.0f);
  return v / std::sqrt(len2);
}

}  // namespace

MaterialNormalMap MaterialNormalMap::from_params(const Params& params) {
  MaterialNormalMap n;
  n.texture = int32_t(params.integer("normal_map", n.texture));
  n.strength = float(params.number("normal_strength", n.strength));
  const std::string space = params.text("normal_space", "TANGENT");
  constexpr std::pair<const char*, NormalMapSpace> kSpaces[] = {{"TANGENT", NormalMapSpace::Tangent},
                                                                {"OBJECT", NormalMapSpace::Object},
                                                                {"WORLD", NormalMapSpace::World},
                                                                {"BLENDER_OBJECT", NormalMapSpace::BlenderObject},
                                                                {"BLENDER_WORLD", NormalMapSpace::BlenderWorld}};
  const auto found =
      std::find_if(std::begin(kSpaces), std::end(kSpaces), [&](const auto& s) { return space == s.first; });
  if (found == std::end(kSpaces))
    throw std::invalid_argument(
        "normal_space must be 'TANGENT', 'OBJECT', 'WORLD', 'BLENDER_OBJECT' or 'BLENDER_WORLD', got '" + space + "'");
  n.space = found->second;
  const std::string convention = params.text("normal_convention", "OPENGL");
  if (convention != "OPENGL" && convention != "DIRECTX")
    throw std::invalid_argument("normal_convention must be 'OPENGL' or 'DIRECTX', got '" + convention + "'");
  n.directx = convention == "DIRECTX";
  const std::string mode = params.text("normal_strength_mode", "tangent");
  if (mode != "tangent" && mode != "blend")
    throw std::invalid_argument("normal_strength_mode must be 'tangent' or 'blend', got '" + mode + "'");
  n.strength_mode = mode == "blend" ? NormalStrength::Blend : NormalStrength::Tangent;
  const std::string shadowing = params.text("normal_shadowing", "conty");
  if (shadowing != "conty" && shadowing != "chiang" && shadowing != "none")
    throw std::invalid_argument("normal_shadowing must be 'conty', 'chiang' or 'none', got '" + shadowing + "'");
  n.shadowing = shadowing == "conty"    ? BumpShadowing::Conty
                : shadowing == "chiang" ? BumpShadowing::Chiang
                                        : BumpShadowing::None;
  n.lift = params.flag("normal_lift", n.lift);
  const int64_t bump = params.integer("bump_map", -1);
  if (bump >= 0 || params.has("bump_strength") || params.has("bump_distance") || params.has("bump_channel") ||
      params.has("bump_footprint")) {
    if (n.texture >= 0) throw std::invalid_argument("a material takes a normal_map or a bump_map, not both");
    n.texture = int32_t(bump);
    n.bump = true;
    n.strength = float(params.number("bump_strength", 1.0));
    n.distance = float(params.number("bump_distance", 1.0));
    const std::string channel = params.text("bump_channel", "gray");
    if (channel != "gray" && channel != "alpha")
      throw std::invalid_argument("bump_channel must be 'gray' or 'alpha', got '" + channel + "'");
    n.bump_alpha = channel == "alpha";
    const std::string footprint = params.text("bump_footprint", "point");
    if (footprint != "point" && footprint != "pixel")
      throw std::invalid_argument("bump_footprint must be 'point' or 'pixel', got '" + footprint + "'");
    n.bump_footprint = footprint == "pixel";
  }
  return n;
}

Vec3 normal_map_vector(const MaterialNormalMap& map, const Vec3& texel) {
  Vec3 n = 2.0f * texel - 1.0f;
  if (map.directx) n.y = -n.y;
  if (map.space == NormalMapSpace::BlenderObject || map.space == NormalMapSpace::BlenderWorld) {
    n.y = -n.y;
    n.z = -n.z;
  }
  return n;
}

Vec3 tangent_space_normal(const MaterialNormalMap& map, Vec3 n, const Vec3& t, float sign, const Vec3& n_smooth) {
  if (map.strength_mode == NormalStrength::Tangent) {
    const float s = map.strength;
    n.x *= s;
    n.y *= s;
    n.z = 1.0f + (n.z - 1.0f) * std::clamp(s, 0.0f, 1.0f);
  }
  const Vec3 b = sign * glm::cross(n_smooth, t);
  return unit_or_zero(n.x * t + n.y * b + n.z * n_smooth);
}

Vec3 blend_normal_strength(const MaterialNormalMap& map, const Vec3& bent, const Vec3& ns) {
  Vec3 n = unit_or_zero(bent);
  const bool blend = map.strength_mode == NormalStrength::Blend || map.space != NormalMapSpace::Tangent || map.bump;
  if (blend && map.strength != 1.0f && n != Vec3(0.0f)) n = unit_or_zero(ns + (n - ns) * std::max(map.strength, 0.0f));
  return n == Vec3(0.0f) ? ns : n;
}

Vec3 valid_reflection_normal(const Vec3& ng, const Vec3& wo, const Vec3& n) {
  const float iz = glm::dot(wo, ng);
  const float threshold = std::min(0.9f * iz, 0.01f);
  const Vec3 r = 2.0f * glm::dot(n, wo) * n - wo;
  // n and -n reflect alike: one under the surface is turned to ng's side, where shading reads it.
  if (glm::dot(ng, r) >= threshold) return glm::dot(n, ng) < 0.0f ? -n : n;
  // In the plane of ng (z) and n (x towards n's tangential part), find n' = (x, z), x^2 + z^2 = 1,
  // whose mirror of wo has the height `threshold`: 2 (x Ix + z Iz) z - Iz = t. Squared, in w = z^2:
  // 4 a w^2 - 2 b w + c = 0 with a = Ix^2 + Iz^2, b = 2 (a + Iz t), c = (Iz + t)^2. Before squaring
  // 2 x z Ix = t + Iz (1 - 2 w), so the root must give the right side Ix's sign: the larger root
  // when Ix < 0, else the smaller.
  const Vec3 x_axis = unit_or_zero(n - glm::dot(n, ng) * ng);
  if (x_axis == Vec3(0.0f)) return ng;  // n along -ng: no plane, the surface normal is valid
  const float ix = glm::dot(wo, x_axis);
  const float a = ix * ix + iz * iz;
  if (!(a > 0.0f)) return ng;
  const float b = 2.0f * (a + iz * threshold);
  const float c = (threshold + iz) * (threshold + iz);
  const float root = std::sqrt(std::max(b * b - 4.0f * a * c, 0.0f));
  const float w = std::clamp(0.25f * (ix < 0.0f ? b + root : b - root) / a, 0.0f, 1.0f);
  const Vec3 out = std::sqrt(1.0f - w) * x_axis + std::sqrt(w) * ng;
  return is_finite(out) ? out : ng;
}

Vec3 bump_normal(const MaterialNormalMap& map, const Vec3& n, const Vec3& dx, const Vec3& dy, float hx, float hy) {
  const Vec3 rx = glm::cross(dy, n), ry = glm::cross(n, dx);
  const float det = glm::dot(dx, rx);
  const Vec3 surface_gradient = hx * rx + hy * ry;
  const Vec3 bent = unit_or_zero(std::fabs(det) * n - map.distance * (det < 0.0f ? -1.0f : 1.0f) * surface_gradient);
  return bent == Vec3(0.0f) ? n : bent;
}

void footprint_axes(const Vec3& ng, Vec3& a, Vec3& b) {
  a = ng.x != ng.y || ng.x != ng.z ? Vec3(ng.z - ng.y, ng.x - ng.z, ng.y - ng.x)
                                   : Vec3(ng.z - ng.y, ng.x + ng.z, -ng.y - ng.x);
  a = glm::normalize(a);
  b = glm::cross(ng, a);
}

}  // namespace toyrt
