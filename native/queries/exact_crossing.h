// The exact ray/triangle crossing test of the multi-hit queries (count, list, occupancy). The
// nearest-hit test of geometry/triangle.h accepts a ray exactly on a shared edge for both
// triangles (right for a nearest hit, wrong for counting); this one decides every tie by one
// rule, so each crossing of a closed surface is counted exactly once.
//
// The model. Vertices are translated to the ray's origin in double (one rounding per vertex at
// most, and the same vertex always rounds the same way), then every decision is an exact sign
// (queries/exact_sign.h) on those translated vertices A, B, C and the direction d:
//   - the ray passes on the left or right of the directed edge (A, B) by the sign of the Plücker
//     product P(A, B) = d . (A x B); it crosses the triangle when P(A,B), P(B,C), P(C,A) have one
//     strict sign. A shared edge is (A, B) in one triangle and (B, A) in the other, and
//     P(B, A) = -P(A, B) exactly, so the two triangles see opposite signs.
//   - ties (P exactly 0: the ray meets the edge's line) are broken by simulation of simplicity
//     (Edelsbrunner and Mücke 1990): the origin is moved by (e, e^2, e^3) for an infinitesimal
//     e > 0. Expanding P(A - delta, B - delta) = P(A, B) + delta . ((A - B) x d), the sign is that
//     of the first nonzero of P, [(A-B) x d].x, .y, .z. This is the answer for one single ray
//     (the perturbed one), for every edge and vertex at once, so a ray through a vertex crosses
//     exactly one triangle of a fan that surrounds it, and a ray grazing a silhouette edge or
//     vertex crosses the surface twice or not at all, never once.
//   - the perturbation leaves P identically zero only when the edge is parallel to d (or the
//     triangle's plane contains d): such a triangle is seen edge-on, the perturbed ray passes
//     beside it, and it is never crossed. That is the rule for rays in a triangle's plane.
//   - the distance t = det(A, B, C) / (P(A,B) + P(B,C) + P(C,A)) has an exact sign, so whether
//     the crossing lies ahead of the origin (t > 0), behind (t < 0) or at it (t = 0: the origin
//     lies on the triangle) is exact; t itself is rounded once to double.
// Exactness holds for the triangles one ray (in one object space) is tested against: a closed
// surface split over several meshes or instances is a consistent surface only where the pieces'
// translated vertices coincide, which different transforms do not guarantee.
#pragma once

#include "queries/exact_sign.h"

#include <limits>

namespace toyrt::queries {

// The ray as the exact model sees it: a float ray converted to double without rounding.
struct ExactRay {
  DVec3 org, dir;
};

// One crossing: t in units of the direction's length, barycentrics p = (1-u-v) p0 + u p1 + v p2,
// and the sign of t (exact: 0 when the origin lies on the triangle).
struct Crossing {
  double t, u, v;
  int t_sign;
};

// The tie-break of a Plücker product that is exactly zero: the terms of the perturbation.
[[gnu::noinline, gnu::cold]] inline int tie_side(const DVec3& d, const DVec3& a, const DVec3& b) {
  // [(a - b) x d]: each component written as four products so no difference is rounded.
  const int sx = four_product_sign(a.y, d.z, b.y, d.z, b.z, d.y, a.z, d.y);
  if (sx != 0) return sx;
  const int sy = four_product_sign(a.z, d.x, b.z, d.x, b.x, d.z, a.x, d.z);
  if (sy != 0) return sy;
  return four_product_sign(a.x, d.y, b.x, d.y, b.y, d.x, a.y, d.x);
}

// sign(P(a, b)) of the perturbed ray, and P(a, b) in double: the filtered sign, else the exact
// sign, else the tie-breaking terms.
inline int edge_side(const DVec3& dir, const DVec3& a, const DVec3& b, double& value) {
  int s = triple_filtered(dir, a, b, value);
  if (s != 2) return s;
  s = triple_sign_exact(dir, a, b);
  return s != 0 ? s : tie_side(dir, a, b);
}

// Whether the perturbed ray crosses the triangle (p0, p1, p2); on a crossing writes it to `out`.
// Both faces count.
inline bool exact_crossing(const ExactRay& r, const Vec3& p0, const Vec3& p1, const Vec3& p2, Crossing& out) {
  const DVec3 a = DVec3(p0) - r.org, b = DVec3(p1) - r.org, c = DVec3(p2) - r.org;
  double w0, w1, w2;  // P(b, c), P(c, a), P(a, b): the weights of p0, p1, p2
  const int side = edge_side(r.dir, a, b, w2);
  if (side == 0 || edge_side(r.dir, b, c, w0) != side || edge_side(r.dir, c, a, w1) != side) return false;
  const double sum = w0 + w1 + w2;
  const double volume = glm::dot(a, glm::cross(b, c));
  out.t_sign = triple_sign(a, b, c) * side;
  // The rounded quotients; sum has the crossing's sign unless every weight rounded to nothing,
  // which the exact signs above rule out for all but denormal geometry: fall back to the centre.
  if (sum != 0.0 && std::isfinite(sum)) {
    out.t = volume / sum;
    out.u = w1 / sum;
    out.v = w2 / sum;
  } else {
    out.t = 0.0;
    out.u = out.v = 1.0 / 3.0;
  }
  // Keep t's rounded value on the side its exact sign names.
  constexpr double tiny = std::numeric_limits<double>::denorm_min();
  if (out.t_sign == 0) {
    out.t = 0.0;
  } else if (sign_of(out.t) != out.t_sign) {
    out.t = out.t_sign > 0 ? tiny : -tiny;
  }
  return true;
}

}  // namespace toyrt::queries
