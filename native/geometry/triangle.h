// Watertight ray/triangle intersection (Woop, Benthin and Wald 2013, "Watertight Ray/Triangle
// Intersection", JCGT 2(1)). The ray is turned into a shear along its dominant axis, so every
// edge test is a 2D orientation test of the same translated vertices; a shared edge gets the
// same value of the same expression from both of its triangles, so a ray through an edge or a
// vertex cannot slip between them. Exact zeros are recomputed in double precision, as the paper
// does, so the sign of an edge function is never decided by a rounding.
#pragma once

#include "core/math.h"

#include <algorithm>
#include <utility>

namespace toyrt {

// Per-ray constants of the shear transform, computed once per traversal.
struct WatertightRay {
  Vec3 org, dir;
  int kx, ky, kz;    // axis permutation: kz is the dominant direction axis
  float sx, sy, sz;  // shear and scale that map the direction to (0, 0, 1)
};

inline WatertightRay make_watertight_ray(const Vec3& org, const Vec3& dir) {
  WatertightRay r;
  r.org = org;
  r.dir = dir;
  r.kz = max_dimension(glm::abs(dir));
  r.kx = (r.kz + 1) % 3;
  r.ky = (r.kx + 1) % 3;
  // Swapping x and y when the dominant component is negative keeps the winding, so the sign
  // convention of U, V, W does not depend on the ray's direction.
  if (dir[r.kz] < 0.0f) std::swap(r.kx, r.ky);
  r.sx = dir[r.kx] / dir[r.kz];
  r.sy = dir[r.ky] / dir[r.kz];
  r.sz = 1.0f / dir[r.kz];
  return r;
}

// Bound on the rounding error of the scaled distance T computed below. pbrt-v4's derivation
// (section 6.8.4: errors of the translated and sheared coordinates, then of the edge functions,
// then of their weighted sum) gives 3 (g3 E Z + de Z + dz E) with dz = g3 Z, dx = g5 (X + Z),
// dy = g5 (Y + Z), de = 2 (g2 X Y + dy X + dx Y), where X, Y, Z and E are the largest magnitudes of
// the sheared x, y, z and of the edge functions, and gN = gamma(N). The bound only grows with each
// of them, so larger stand-ins keep it conservative, and two are cheaper (the block test computes
// this for eight lanes at every leaf a ray leaves): M = max(X, Y) for both X and Y, and |det| for E
// (a candidate's edge functions share one sign, so their float sum is at least as large as each:
// rounding is monotone). That is 3 Z (2 g3 |det| + 2 g2 M^2 + 4 g5 (M + Z) M). Its own float
// evaluation (a dozen operations on non-negative values, each rounded by at most 2^-24) is
// covered by rounding the factor 3 up by 2^-18.
// pbrt's bound is for tnear = 0, where only the signs of T and det matter. The test compares T
// with tnear |det|, so for tnear != 0 (never the renderer's rays, whose tnear is 0) det's own error
// counts too: three edge functions, each within the edge error above, two sums and the product
// with tnear: |tnear| (3 de + g4 |det|), with the same rounding up (which also covers the
// subtraction's rounding of T - tnear |det|: one 2^-24 of a value near the bound). The term is
// added whatever tnear (0 when it is 0; a branch on tnear cost as much). Where a product overflows
// the bound is infinite or NaN, and every comparison with it sends the lane to double.
// A T within the bound of tnear |det| may really be on the other side of the ray's start; those
// few are decided in double. F is float or a vector of floats.
template <class F>
inline F near_start_error(F max_xy, F max_z, F abs_det, float tnear) {
  constexpr float three = 3.0f * (1.0f + 0x1p-18f);
  const F edge_error = (2.0f * gamma(2)) * max_xy * max_xy + (4.0f * gamma(5)) * (max_xy + max_z) * max_xy;
  return (three * max_z) * ((2.0f * gamma(3)) * abs_det + edge_error) +
         (three * std::fabs(tnear)) * (edge_error + (gamma(5) / 3.0f) * abs_det);
}

// Whether a candidate's crossing is surely past the ray's start (1), surely before it (-1), or
// for the error bound to decide (0), from the scaled z of its vertices alone. Each z is
// sz (p_z - o_z) along the dominant axis, whose sign is exact (a float difference is zero only
// for equal operands and keeps the sign; so does the product), so z > 0 at every vertex says the
// whole triangle lies strictly ahead of the origin's plane across that axis. The crossing the
// float test found, T / det, is the sum of the edge functions times the z's; a candidate's edge
// functions share one sign, so no term cancels and it lies ahead too, at a distance within the
// triangle's span. So with tnear <= 0 such a hit is past the start; likewise all z < 0 with
// tnear >= 0 is behind it. A ray the test lets in while it truly passes outside (within the
// rounding of its shear: a ray starting within rounding of the triangle) is so decided by the
// configuration that decided inside and outside, where the bound would have asked where the
// true plane crosses the ray (docs/core.md). A determinant that overflowed (coordinates near
// 1e19) leaves T / det meaningless: the bound and double precision decide those. Camera rays at
// 10K triangles: 4 % of their time was the bound (docs/trace-speed.md, thirty-sixth session).
inline int start_side(float az, float bz, float cz, float abs_det, float tnear) {
  if (!(abs_det <= std::numeric_limits<float>::max())) return 0;
  if (tnear <= 0.0f && az > 0.0f && bz > 0.0f && cz > 0.0f) return 1;
  if (tnear >= 0.0f && az < 0.0f && bz < 0.0f && cz < 0.0f) return -1;
  return 0;
}

// The hit test for a candidate whose float distance is too close to tnear to trust: the plane
// crossing in double precision (Moller-Trumbore on the same float inputs). The float test has
// already placed the ray inside the triangle, so only the distance is decided here.
[[gnu::noinline, gnu::cold]] inline bool near_start_in_double(const WatertightRay& r, const Vec3& p0, const Vec3& p1,
                                                              const Vec3& p2, float tnear, float tfar, float& t,
                                                              float& u, float& v) {
  const DVec3 o(r.org), d(r.dir), a(p0);
  const DVec3 e1 = DVec3(p1) - a, e2 = DVec3(p2) - a;
  const DVec3 pv = glm::cross(d, e2);
  const double det = glm::dot(e1, pv);
  if (det == 0.0) return false;  // the ray lies in the plane: no crossing distance
  const DVec3 tv = o - a, qv = glm::cross(tv, e1);
  const double td = glm::dot(e2, qv) / det;
  if (!(td >= double(tnear) && td < double(tfar))) return false;
  t = std::max(float(td), tnear);
  u = float(glm::dot(tv, pv) / det);
  v = float(glm::dot(d, qv) / det);
  return true;
}

// Edge functions recomputed in double when a float one came out exactly zero. Products of two
// floats are exact in double, and a correctly rounded difference keeps the exact sign (and is
// zero only when the products are equal), so these signs are the true ones. Returns whether the
// signs agree (the ray passes inside or on the boundary), and writes the values back.
[[gnu::noinline, gnu::cold]] inline bool edge_signs_in_double(float ax, float ay, float bx, float by, float cx,
                                                              float cy, float& eu, float& ev, float& ew) {
  const double du = double(cx) * double(by) - double(cy) * double(bx);
  const double dv = double(ax) * double(cy) - double(ay) * double(cx);
  const double dw = double(bx) * double(ay) - double(by) * double(ax);
  if ((du < 0.0 || dv < 0.0 || dw < 0.0) && (du > 0.0 || dv > 0.0 || dw > 0.0)) return false;
  eu = static_cast<float>(du);
  ev = static_cast<float>(dv);
  ew = static_cast<float>(dw);
  return true;
}

// Tests the triangle against the ray segment [tnear, tfar). On a hit, writes t and the
// barycentrics u, v with p = (1 - u - v) p0 + u p1 + v p2, and returns true. Both faces count.
// A degenerate (zero-area) triangle never hits: its determinant is zero.
[[gnu::always_inline]] inline bool intersect_triangle(const WatertightRay& r, const Vec3& p0, const Vec3& p1,
                                                      const Vec3& p2, float tnear, float tfar, float& t, float& u,
                                                      float& v) {
  const Vec3 a = p0 - r.org, b = p1 - r.org, c = p2 - r.org;
  const float ax = a[r.kx] - r.sx * a[r.kz], ay = a[r.ky] - r.sy * a[r.kz];
  const float bx = b[r.kx] - r.sx * b[r.kz], by = b[r.ky] - r.sy * b[r.kz];
  const float cx = c[r.kx] - r.sx * c[r.kz], cy = c[r.ky] - r.sy * c[r.kz];

  // Scaled barycentrics: U weights p0, V weights p1, W weights p2.
  float eu = cx * by - cy * bx;
  float ev = ax * cy - ay * cx;
  float ew = bx * ay - by * ax;
  if (__builtin_expect(eu == 0.0f || ev == 0.0f || ew == 0.0f, 0)) {
    // The float products may have cancelled: decide the edge signs exactly.
    if (!edge_signs_in_double(ax, ay, bx, by, cx, cy, eu, ev, ew)) return false;
  } else if ((eu < 0.0f || ev < 0.0f || ew < 0.0f) && (eu > 0.0f || ev > 0.0f || ew > 0.0f)) {
    return false;
  }

  const float det = eu + ev + ew;
  if (det == 0.0f) return false;

  const float az = r.sz * a[r.kz], bz = r.sz * b[r.kz], cz = r.sz * c[r.kz];
  const float scaled_t = eu * az + ev * bz + ew * cz;
  // Compare in the scaled domain to avoid the division for rejected hits.
  const float abs_det = std::fabs(det);
  const float signed_t = det < 0.0f ? -scaled_t : scaled_t;
  if (!(signed_t < tfar * abs_det)) return false;
  // A triangle wholly on one side of the ray's origin along the dominant axis needs no error
  // bound (start_side). Else the bound decides, and where it cannot, double precision does.
  const int side = start_side(az, bz, cz, abs_det, tnear);
  if (side < 0) return false;
  if (side == 0) {
    const float past_start = signed_t - tnear * abs_det;
    const float max_xy =
        std::max({std::fabs(ax), std::fabs(bx), std::fabs(cx), std::fabs(ay), std::fabs(by), std::fabs(cy)});
    const float max_z = std::max({std::fabs(az), std::fabs(bz), std::fabs(cz)});
    const float error = near_start_error(max_xy, max_z, abs_det, tnear);
    if (!(past_start > error)) {
      // As far before tnear as the bound: surely behind the start (the same bound as the accept).
      if (past_start < -error) return false;
      // Too close to tnear for float to tell which side the triangle is on: a ray leaving a
      // sliver, or a grazing one. Decide in double, where the answer is reliable.
      return near_start_in_double(r, p0, p1, p2, tnear, tfar, t, u, v);
    }
  }

  const float inv_det = 1.0f / det;
  t = scaled_t * inv_det;
  u = ev * inv_det;
  v = ew * inv_det;
  return true;
}

// Recomputes t, u, v of an accepted hit in double precision (Moller-Trumbore on the same float
// inputs). The float test above decides hit or miss watertightly, but its t and barycentrics come
// from edge functions that cancel badly on slivers and grazing hits (relative errors up to 1e-3
// on a 1e4:1 sliver); one double evaluation per ray, for the nearest hit only, makes them
// accurate to float precision. u and v are those of the true crossing point, so for a grazing
// hit that rounding let in they may lie outside [0, 1] by as much as the point lies outside the
// triangle (a distance of rounding size, though on a sliver that is a visible fraction of its
// narrow barycentric range); clamping them would move the point along the sliver instead.
inline void refine_hit(const Vec3& org, const Vec3& dir, const Vec3& p0, const Vec3& p1, const Vec3& p2, float tnear,
                       float& t, float& u, float& v) {
  const DVec3 o(org), d(dir), a(p0);
  const DVec3 e1 = DVec3(p1) - a, e2 = DVec3(p2) - a;
  const DVec3 pv = glm::cross(d, e2);
  const double det = glm::dot(e1, pv);
  if (det == 0.0) return;  // the ray lies in the triangle's plane: keep the float answer
  const double inv = 1.0 / det;
  const DVec3 tv = o - a, qv = glm::cross(tv, e1);
  // Never before the start. A plane crossing before it with the float test's crossing past it is
  // a ray that rounding let into a triangle start_side found wholly ahead while it truly passes
  // outside (it starts within rounding of the triangle, or lies nearly in its plane): the float
  // distance, which lies within the triangle's span along the ray, stays.
  const float refined = float(glm::dot(e2, qv) * inv);
  t = refined >= tnear ? refined : std::max(t, tnear);
  u = float(glm::dot(tv, pv) * inv);
  v = float(glm::dot(d, qv) * inv);
}

}  // namespace toyrt
