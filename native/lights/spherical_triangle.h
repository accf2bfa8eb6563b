// Uniform sampling of the solid angle a triangle subtends from a point: Arvo 1995, "Stratified
// Sampling of Spherical Triangles" (SIGGRAPH). Every direction towards the triangle has density
// 1 / Omega, so a shading point right beside an emissive triangle (a floor under a glowing ball)
// gets no 1 / r^2 spikes, which area sampling gives there and which dominate its noise.
//
// With A, B, C the unit directions to the vertices and alpha, beta, gamma the spherical triangle's
// angles at them (Girard: Omega = alpha + beta + gamma - pi), a first number picks the sub-triangle
// A B C' of solid angle u0 Omega, C' on the arc A C: with s, t the sine and cosine of
// u0 Omega - alpha, u = t - cos(alpha) and v = s + sin(alpha) cos(c) (c the arc A B),
//     cos(arc A C') = q = ((v t - u s) cos(alpha) - v) / ((v s + u t) sin(alpha)),
// and a second number picks the point on the arc B C' by its cosine to B, linear in u1.
//
// Computed in double (the angles through atan2 of the tangent vectors, not acos). Below
// kMinSolidAngle a triangle is effectively a point and callers sample its area instead.
#pragma once

#include "core/math.h"
#include "sampling/warp.h"

namespace toyrt {

struct SphericalTriangle {
  static constexpr double kMinSolidAngle = 1e-5;  // sr

  DVec3 a, b, c;  // unit directions to the vertices
  double alpha = 0.0, cos_c = 0.0, solid_angle = 0.0;

  // From point p to the triangle (v0, v1, v2); solid_angle 0 when it is degenerate or seen edge-on.
  static SphericalTriangle make(const Vec3& p, const Vec3& v0, const Vec3& v1, const Vec3& v2);
  // A unit direction for two uniform numbers, uniform in solid angle (density 1 / solid_angle).
  Vec3 sample(const Vec2& u) const;
};

}  // namespace toyrt
