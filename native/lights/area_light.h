// Blender's area light in Cycles' units: a one-sided rectangle, square, disk or ellipse emitting
// along its local -Z with uniform radiance
//     L = P colour / (4 area)      (not the textbook Lambertian P / (pi area))
// as measured in BLENDER_UNITS.md: 100 W from a 5 cm square 1 m above a white plane gives a pixel
// of 7.950 = (1 / pi) L area / 1 m^2, i.e. irradiance P / 4; Cycles' sync scales the power of
// area lights by 1/4 where point lights get 1 / (4 pi). The size comes from Blender's size
// (and size_y), times the object's scale, as in Cycles; the power stays the same, so scaling a
// light up dims its radiance.
//
// Sampling: rectangles and squares by either estimator (AreaSampling), disks and ellipses by area.
// The estimator is a render setting (IntegratorSettings::area_sampling), passed to sample() and
// evaluate() in the LightContext, not part of the light: one scene renders with either.
//
// Parameters (add_light('AREA', ...), Blender's names): matrix (the object's (4, 4) world
// matrix, identity), shape ('SQUARE'), size (1 m), size_y (size; RECTANGLE and ELLIPSE only,
// accepted and ignored otherwise), power (10 W), color ((1, 1, 1)), spread (radians, pi: no slats;
// lights/area_spread.h): AreaLight::Settings.
#pragma once

#include "core/params.h"
#include "lights/area_spread.h"
#include "lights/light_bounds.h"
#include "lights/light_context.h"
#include "lights/light_sample.h"
#include "sampling/warp.h"

#include <string>

namespace toyrt {

enum class AreaShape { Rectangle, Square, Disk, Ellipse };  // Blender's shape enum

struct AreaLight {
  static constexpr const char* kType = "AREA";  // Blender's light type
  static constexpr const char* kParams =
      "matrix ((4, 4) world matrix, identity; emits along local -Z), shape ('RECTANGLE', 'SQUARE', 'DISK',\n"
      "    'ELLIPSE'; 'SQUARE'), size (m, 1), size_y (m, size; RECTANGLE and ELLIPSE), power (W, 10),\n"
      "    color (linear RGB, (1, 1, 1)), spread (radians > 0; pi: no slats)";

  // Blender's settings, with the defaults of a new area light: a 1 m square of 10 W, white.
  struct Settings {
    Mat4 matrix{1.0f};  // the object's world matrix
    AreaShape shape = AreaShape::Square;
    float size = 1.0f;    // m
    float size_y = 1.0f;  // m, RECTANGLE and ELLIPSE only; from_params defaults it to size
    float power = 10.0f;  // W
    Vec3 color{1.0f};
    float spread = kPi;  // radians; pi: a plain light
  };

  AreaShape shape = AreaShape::Rectangle;
  Vec3 center{0.0f};
  Vec3 edge_x{1.0f, 0.0f, 0.0f}, edge_y{0.0f, 1.0f, 0.0f};  // full extents along local x and y (orthogonal)
  Vec3 normal{0.0f, 0.0f, -1.0f};                           // unit, the emitting side
  float area = 1.0f;                                        // m^2 (pi/4 |edge_x| |edge_y| for disks and ellipses)
  Vec3 radiance{0.0f};                                      // L = P colour / (4 area), W / (m^2 sr)
  AreaSpread spread;                                        // radiance x spread.factor(cos) in each direction

  // Blender's settings: shape; size (and size_y for RECTANGLE and ELLIPSE; SQUARE and DISK use
  // size for both, a disk's size being its diameter); the object's world matrix; power (W);
  // colour; spread (at or above pi: no slats). Throws std::invalid_argument for non-positive sizes,
  // negative power or colour, a spread that is not a positive number, a non-finite or non-affine matrix, a zero or
  // sheared scale (the light must stay a rectangle).
  static AreaLight make(AreaShape shape, float size, float size_y, const Mat4& matrix_world, float power,
                        const Vec3& color, float spread = kPi);
  // From Params named as Settings' members (shape as Blender's name); size_y defaults to size.
  static AreaLight from_params(const Params& params);

  bool is_rectangle() const { return shape == AreaShape::Rectangle || shape == AreaShape::Square; }
  Vec3 corner() const { return center - 0.5f * edge_x - 0.5f * edge_y; }
};

// A point on the light seen from shading point p (u: two uniform numbers). No sample when p is
// behind or in the light's plane.
// ctx.area_sampling applies to rectangles and squares; other shapes are always sampled by area.
LightSample sample(const AreaLight& light, const Vec3& p, const Vec2& u, const LightContext& ctx);
// The light along direction wi from p, with the density `sample` would have given wi.
LightEval evaluate(const AreaLight& light, const Vec3& p, const Vec3& wi, const LightContext& ctx);

// Blender's shape names: "RECTANGLE", "SQUARE", "DISK", "ELLIPSE"; throws std::invalid_argument.
AreaShape parse_area_shape(const std::string& name);
const char* area_shape_name(AreaShape shape);
// "solid_angle" and "area"; throws std::invalid_argument.
AreaSampling parse_area_sampling(const std::string& name);
const char* area_sampling_name(AreaSampling sampling);
// The light's expected contribution at p with normal n (n = 0: no receiver cosine), for light
// selection: mean (L area) over distance^2, times bounds of the emitter's and the receiver's
// cosines over the light's bounding sphere. Zero exactly when p is not in front of the light or
// the whole bounding sphere is below p's tangent plane.
float importance(const AreaLight& light, const Vec3& p, const Vec3& n);
// The rectangle's box (a disk's or ellipse's enclosing one), normals along `normal` only
// (theta_o = 0) emitting over the hemisphere, with L area as power (the intensity along the normal).
LightBounds bounds(const AreaLight& light);

}  // namespace toyrt
