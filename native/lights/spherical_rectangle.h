// Uniform sampling of the solid angle a rectangle subtends from a point: Urena, Fajardo and King
// 2013, "An Area-Preserving Parametrization for Spherical Rectangles" (EGSR). Every direction
// towards the rectangle has the same density 1 / Omega, so the only variance left in a
// direct-lighting estimate comes from the cosines and the BSDF, not from the 1 / r^2 of area
// sampling, which dominates close to a large light.
//
// The math, as derived here from the paper's construction. In a frame at p with x, y along the
// rectangle's edges and the rectangle at z = z0 < 0 spanning [x0, x1] x [y0, y1], the four planes
// through p and an edge have normals n0..n3 and the spherical rectangle's interior angles are
// g_i = angle between consecutive planes, so Omega = g0 + g1 + g2 + g3 - 2 pi (Girard). The
// solid angle of the sub-rectangle [x0, xu] x [y0, y1] is
//     A(xu) = g2 + g3 - 2 pi + acos(-b0 c) + acos(-b1 c),   c = xu / sqrt(xu^2 + z0^2),
// with b0 = n0.z and b1 = n2.z (the angles at the moving corners). Solving A(xu) = u Omega with
// phi = u Omega + 2 pi - g2 - g3 = acos(-b0 c) + acos(-b1 c) gives, by the cosine of a sum,
//     c = sign(f) / sqrt(f^2 + b0^2),   f = (b0 cos(phi) - b1) / sin(phi),
// and xu = -c z0 / sqrt(1 - c^2). Along the line x = xu the solid angle per unit y is
// proportional to d(h)/dy for h = y / sqrt(d^2 + y^2), d^2 = xu^2 + z0^2, so h is drawn
// uniformly between its values at y0 and y1 and inverted: y = h d / sqrt(1 - h^2).
//
// Precision: everything runs in double, and the interior angles come from atan2(|n_a x n_b|,
// -n_a . n_b) instead of acos, which loses half its digits near 0 and pi (a point near the light's
// plane). Below a solid angle of kMinSolidAngle the light is effectively a point and callers use
// area sampling, whose density is then constant to within 1e-3 anyway.
#pragma once

#include "core/math.h"
#include "sampling/warp.h"

namespace toyrt {

struct SphericalRectangle {
  static constexpr double kMinSolidAngle = 1e-6;  // sr

  DVec3 origin{0.0}, x{0.0}, y{0.0}, z{0.0};  // the frame at the shading point
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0, z0 = 0;
  double b0 = 0, b1 = 0, k = 0;
  double solid_angle = 0.0;  // sr; 0 when p lies in the rectangle's plane

  // The rectangle corner + a edge_x + b edge_y (a, b in [0, 1]) seen from p; the edges must be
  // orthogonal.
  static SphericalRectangle make(const Vec3& p, const Vec3& corner, const Vec3& edge_x, const Vec3& edge_y);
  // The point on the rectangle in direction of the u-th uniform solid-angle sample.
  Vec3 sample(const Vec2& u) const;
};

}  // namespace toyrt
