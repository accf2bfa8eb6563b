#include "scene/instance_bounds.h"

#include <algorithm>
#include <cmath>

namespace toyrt {
namespace {

// gamma(8) in double: the float operations of a ray's transform (4 terms per coordinate), of
// the watertight test's translation and shear, with room to spare.
constexpr double kGamma8 = 8.0 * 0x1p-24 / (1.0 - 8.0 * 0x1p-24);

// A float no smaller than x (the bounds below are computed in double; each becomes a float pad).
float round_up(double x) {
  const float f = float(x);
  return double(f) >= x ? f : std::nextafter(f, kInfinity);
}

}  // namespace

TransformError transform_error(const Mat4& to_world, const Mat4& to_object) {
  // glm is column-major: m[column][row]. Products of two floats are exact in double, and the
  // sums' own rounding (1e-16 relative) is far inside the factor 2 of the pads.
  TransformError e;
  double ab_norm = 0.0, a_norm = 0.0, ab_abs_b = 0.0, g_norm = 0.0;
  for (int r = 0; r < 3; ++r) {
    double f_row = 0.0, ab_row = 0.0, a_row = 0.0, a_abs_b = 0.0;
    double g = double(to_world[3][r]);
    for (int c = 0; c < 3; ++c) {
      double product = 0.0, abs_product = 0.0;
      for (int j = 0; j < 3; ++j) {
        product += double(to_world[j][r]) * double(to_object[c][j]);
        abs_product += std::fabs(double(to_world[j][r])) * std::fabs(double(to_object[c][j]));
      }
      f_row += std::fabs(product - (r == c ? 1.0 : 0.0));
      ab_row += abs_product;
      a_row += std::fabs(double(to_world[c][r]));
      g += double(to_world[c][r]) * double(to_object[3][c]);
      a_abs_b += std::fabs(double(to_world[c][r])) * std::fabs(double(to_object[3][c]));
    }
    e.inverse = std::max(e.inverse, f_row);
    ab_norm = std::max(ab_norm, ab_row);
    a_norm = std::max(a_norm, a_row);
    ab_abs_b = std::max(ab_abs_b, a_abs_b);
    g_norm = std::max(g_norm, std::fabs(g));
  }
  e.spread = kGamma8 * ab_norm;
  e.offset = g_norm + kGamma8 * ab_abs_b;
  e.reach = kGamma8 * a_norm;
  return e;
}

BBox instance_world_bounds(const BBox& b, const Mat4& to_world, const TransformError& error) {
  BBox world;
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 p((corner & 1) ? b.hi.x : b.lo.x, (corner & 2) ? b.hi.y : b.lo.y, (corner & 4) ? b.hi.z : b.lo.z);
    world.extend(Vec3(to_world * glm::vec4(p, 1.0f)));
  }
  // The transformed corners are rounded: a few ulps of their magnitude keep the box around the
  // exact image of the mesh box.
  const Vec3 rounding = (glm::abs(world.lo) + glm::abs(world.hi)) * (4.0f * gamma(4));
  world.lo -= rounding;
  world.hi += rounding;
  const auto largest = [](const BBox& box) {
    const Vec3 m = glm::max(glm::abs(box.lo), glm::abs(box.hi));
    return double(std::max({m.x, m.y, m.z}));
  };
  // The instance's own pad (instance_bounds.h): 2 ((f + k) M + c).
  const double c = error.offset + error.reach * largest(b);
  const float pad = round_up(2.0 * ((error.inverse + error.spread) * largest(world) + c));
  world.lo -= Vec3(pad);
  world.hi += Vec3(pad);
  return world;
}

float origin_pad_factor(const TransformError& error) { return round_up(4.0 * error.spread); }

}  // namespace toyrt
