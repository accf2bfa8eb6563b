// The watertight ray/triangle test on its own: conventions, ranges, degenerate input, and the
// watertightness property on a shared edge.
#include "geometry/triangle.h"

#include <gtest/gtest.h>

#include <random>

using namespace toyrt;

namespace {
bool hit(const Vec3& o, const Vec3& d, const Vec3& p0, const Vec3& p1, const Vec3& p2, float& t, float& u, float& v,
         float tnear = 0.0f, float tfar = kInfinity) {
  return intersect_triangle(make_watertight_ray(o, d), p0, p1, p2, tnear, tfar, t, u, v);
}
}  // namespace

TEST(Triangle, BarycentricsFollowEmbreeConvention) {
  const Vec3 p0(0, 0, 0), p1(2, 0, 0), p2(0, 2, 0);
  float t, u, v;
  // Aim at p = 0.5 p0 + 0.25 p1 + 0.25 p2 = (0.5, 0.5, 0) from 3 units above.
  ASSERT_TRUE(hit({0.5f, 0.5f, 3.0f}, {0, 0, -1}, p0, p1, p2, t, u, v));
  EXPECT_FLOAT_EQ(t, 3.0f);
  EXPECT_FLOAT_EQ(u, 0.25f);
  EXPECT_FLOAT_EQ(v, 0.25f);
}

TEST(Triangle, DistanceIsInUnitsOfTheDirection) {
  float t, u, v;
  ASSERT_TRUE(hit({0.2f, 0.2f, 4.0f}, {0, 0, -2}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, t, u, v));
  EXPECT_FLOAT_EQ(t, 2.0f);
}

TEST(Triangle, BothFacesAreHit) {
  float t, u, v;
  EXPECT_TRUE(hit({0.2f, 0.2f, 1.0f}, {0, 0, -1}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, t, u, v));
  EXPECT_TRUE(hit({0.2f, 0.2f, -1.0f}, {0, 0, 1}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, t, u, v));
}

TEST(Triangle, MissesOutsideAndBehind) {
  float t, u, v;
  EXPECT_FALSE(hit({0.8f, 0.8f, 1.0f}, {0, 0, -1}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, t, u, v));
  EXPECT_FALSE(hit({0.2f, 0.2f, 1.0f}, {0, 0, 1}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, t, u, v));
}

TEST(Triangle, SegmentIsHalfOpen) {
  float t, u, v;
  const Vec3 o(0.2f, 0.2f, 1.0f), d(0, 0, -1), p0(0, 0, 0), p1(1, 0, 0), p2(0, 1, 0);
  EXPECT_TRUE(hit(o, d, p0, p1, p2, t, u, v, 1.0f, 2.0f));   // t == tnear counts
  EXPECT_FALSE(hit(o, d, p0, p1, p2, t, u, v, 0.0f, 1.0f));  // t == tfar does not
  EXPECT_FALSE(hit(o, d, p0, p1, p2, t, u, v, 1.5f, 2.0f));
}

TEST(Triangle, DegenerateNeverHits) {
  float t, u, v;
  // Collinear and coincident vertices, aimed at along every axis.
  for (const Vec3& d : {Vec3(0, 0, -1), Vec3(0, -1, 0), Vec3(-1, 0, 0), Vec3(-1, -1, -1)}) {
    EXPECT_FALSE(hit(Vec3(0.5f) - d, d, {0, 0, 0}, {1, 1, 1}, {2, 2, 2}, t, u, v));
    EXPECT_FALSE(hit(Vec3(0.5f) - d, d, {0.5f, 0.5f, 0.5f}, {0.5f, 0.5f, 0.5f}, {0.5f, 0.5f, 0.5f}, t, u, v));
  }
}

// A quad split along its diagonal: every ray aimed at a point of the diagonal hits at least one
// of the two triangles. A non-watertight test lets a fraction of these through.
TEST(Triangle, SharedEdgeNeverLetsARayThrough) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f), sym(-1.0f, 1.0f);
  int misses = 0;
  for (int i = 0; i < 200000; ++i) {
    const Vec3 a(sym(rng), sym(rng), sym(rng)), c(sym(rng), sym(rng), sym(rng));
    const Vec3 b(sym(rng), sym(rng), sym(rng)), d(sym(rng), sym(rng), sym(rng));
    const float s = unit(rng);
    const Vec3 target = a + s * (c - a);  // on the shared edge a-c
    const Vec3 org = target + 3.0f * Vec3(sym(rng), sym(rng), sym(rng));
    float t, u, v;
    const bool h = hit(org, target - org, a, b, c, t, u, v) || hit(org, target - org, a, c, d, t, u, v);
    // Only count rays for which the quad is not folded so that the edge is a silhouette.
    const Vec3 n1 = glm::cross(b - a, c - a), n2 = glm::cross(c - a, d - a), dir = target - org;
    if ((glm::dot(n1, dir) > 0) == (glm::dot(n2, dir) > 0) && !h) ++misses;
  }
  EXPECT_EQ(misses, 0);
}

namespace {

// The float quantities of intersect_triangle for one ray and triangle, computed as it does, with
// the magnitudes the near-start bound takes.
struct ScaledDistance {
  bool candidate = false;     // the edge functions share one sign, none zero
  bool exact_inside = false;  // and so do those computed without rounding: the ray crosses the triangle
  float signed_t = 0, abs_det = 0, max_xy = 0, max_z = 0;
  float z[3] = {0, 0, 0};  // the scaled z of the vertices
  double pbrt_bound = 0;   // pbrt-v4's bound from the largest x, y, z and edge function, in double
  long double exact_signed_t = 0, exact_abs_det = 0;
};

ScaledDistance scaled_distance(const WatertightRay& r, const Vec3& p0, const Vec3& p1, const Vec3& p2) {
  ScaledDistance s;
  const Vec3 p[3] = {p0, p1, p2};
  float x[3], y[3], z[3];
  long double xe[3], ye[3], ze[3];  // the same transform without rounding (long double's 64 bits)
  for (int k = 0; k < 3; ++k) {
    const Vec3 a = p[k] - r.org;
    x[k] = a[r.kx] - r.sx * a[r.kz];
    y[k] = a[r.ky] - r.sy * a[r.kz];
    z[k] = r.sz * a[r.kz];
    const long double ax = (long double)p[k][r.kx] - r.org[r.kx], ay = (long double)p[k][r.ky] - r.org[r.ky],
                      az = (long double)p[k][r.kz] - r.org[r.kz];
    xe[k] = ax - (long double)r.sx * az;
    ye[k] = ay - (long double)r.sy * az;
    ze[k] = (long double)r.sz * az;
  }
  const float e[3] = {x[2] * y[1] - y[2] * x[1], x[0] * y[2] - y[0] * x[2], x[1] * y[0] - y[1] * x[0]};
  const long double ee[3] = {xe[2] * ye[1] - ye[2] * xe[1], xe[0] * ye[2] - ye[0] * xe[2],
                             xe[1] * ye[0] - ye[1] * xe[0]};
  const bool all_positive = e[0] > 0 && e[1] > 0 && e[2] > 0, all_negative = e[0] < 0 && e[1] < 0 && e[2] < 0;
  s.candidate = all_positive || all_negative;
  s.exact_inside = (ee[0] > 0 && ee[1] > 0 && ee[2] > 0) || (ee[0] < 0 && ee[1] < 0 && ee[2] < 0);
  for (int k = 0; k < 3; ++k) s.z[k] = z[k];
  const float det = e[0] + e[1] + e[2];
  const float scaled_t = e[0] * z[0] + e[1] * z[1] + e[2] * z[2];
  s.abs_det = std::fabs(det);
  s.signed_t = det < 0 ? -scaled_t : scaled_t;
  const long double exact_t = ee[0] * ze[0] + ee[1] * ze[1] + ee[2] * ze[2];
  s.exact_signed_t = det < 0 ? -exact_t : exact_t;
  s.exact_abs_det = std::fabs(ee[0] + ee[1] + ee[2]);
  double mx = 0, my = 0, mz = 0, me = 0;
  for (int k = 0; k < 3; ++k) {
    mx = std::max(mx, double(std::fabs(x[k])));
    my = std::max(my, double(std::fabs(y[k])));
    mz = std::max(mz, double(std::fabs(z[k])));
    me = std::max(me, double(std::fabs(e[k])));
  }
  s.max_xy = float(std::max(mx, my));
  s.max_z = float(mz);
  const double g2 = gamma(2), g3 = gamma(3), g5 = gamma(5);
  const double dz = g3 * mz, dx = g5 * (mx + mz), dy = g5 * (my + mz);
  const double de = 2 * (g2 * mx * my + dy * mx + dx * my);
  s.pbrt_bound = 3 * (g3 * me * mz + de * mz + dz * me);
  return s;
}

// Random triangles of size `scale` (vertices within it of a centre), up to a thousand sizes from
// the origin: a ray set's generator and its distributions.
struct RandomTriangles {
  std::mt19937 rng;
  std::uniform_real_distribution<float> unit{0.0f, 1.0f}, sym{-1.0f, 1.0f};

  explicit RandomTriangles(uint32_t seed) : rng(seed) {}
  Vec3 point() { return Vec3(sym(rng), sym(rng), sym(rng)); }
  void next(float scale, Vec3& p0, Vec3& p1, Vec3& p2) {
    const Vec3 centre = scale * std::pow(10.0f, 3.0f * unit(rng)) * point();
    p0 = centre + scale * point();
    p1 = centre + scale * point();
    p2 = centre + scale * point();
  }
};

// Rays that start on or near a random triangle (as rays leaving a surface do), at scales from
// 1e-4 to 1e4, up to a thousand triangle sizes from the origin, with directions of any length:
// the cases near_start_error decides.
template <class Check>
void for_rays_leaving_triangles(Check&& check) {
  RandomTriangles g(11);
  auto& unit = g.unit;
  auto& sym = g.sym;
  auto& rng = g.rng;
  for (int i = 0; i < 200000; ++i) {
    const float scale = std::pow(10.0f, float(i % 9) - 4.0f);
    Vec3 p0, p1, p2;
    g.next(scale, p0, p1, p2);
    const float a = unit(rng), b = unit(rng) * (1 - a);
    const Vec3 on = p0 + a * (p1 - p0) + b * (p2 - p0);
    const Vec3 org = on + scale * std::pow(10.0f, -6.0f * unit(rng)) * Vec3(sym(rng), sym(rng), sym(rng));
    // Directions are not normalised (a mesh traces the object-space direction an instance's
    // matrix gives it): lengths from 1e-3 to 1e3.
    const Vec3 dir = std::pow(10.0f, float(i % 7) - 3.0f) * Vec3(sym(rng), sym(rng), sym(rng));
    if (dir == Vec3(0.0f)) continue;
    check(make_watertight_ray(org, dir), p0, p1, p2);
  }
}

// Rays from afar (a camera's): origins 1 to 10^4 triangle sizes away, aimed at points in and
// around a random triangle, at scales from 1e-4 to 1e4, some with the triangle behind them.
template <class Check>
void for_rays_from_afar(Check&& check) {
  RandomTriangles g(13);
  for (int i = 0; i < 100000; ++i) {
    const float scale = std::pow(10.0f, float(i % 9) - 4.0f);
    Vec3 p0, p1, p2;
    g.next(scale, p0, p1, p2);
    const float a = 1.2f * g.unit(g.rng), b = 1.2f * g.unit(g.rng) * (1 - a);  // a few just outside
    const Vec3 aim = p0 + a * (p1 - p0) + b * (p2 - p0);
    const Vec3 org = aim + scale * std::pow(10.0f, 4.0f * g.unit(g.rng)) * g.point();
    const Vec3 dir = (i % 4 == 3 ? -1.0f : 1.0f) * (aim - org);  // one in four looks away
    if (dir == Vec3(0.0f)) continue;
    check(make_watertight_ray(org, dir), p0, p1, p2);
  }
}

}  // namespace

// near_start_error replaces pbrt's largest x, y and edge function by larger stand-ins; it must
// never come out below pbrt's bound (evaluated here in double from the same float inputs).
TEST(Triangle, NearStartErrorIsAtLeastPbrtsBound) {
  int candidates = 0, below = 0;
  for_rays_leaving_triangles([&](const WatertightRay& r, const Vec3& p0, const Vec3& p1, const Vec3& p2) {
    const ScaledDistance s = scaled_distance(r, p0, p1, p2);
    if (!s.candidate) return;
    ++candidates;
    if (double(near_start_error(s.max_xy, s.max_z, s.abs_det, 0.0f)) < s.pbrt_bound) ++below;
  });
  EXPECT_GT(candidates, 50000);
  EXPECT_EQ(below, 0);
}

// The property the bound is for: the float scaled distance lies within it of the one computed
// from the same inputs without rounding, so at tnear = 0 a hit it calls clear of the start is.
TEST(Triangle, NearStartErrorBoundsTheScaledDistancesRounding) {
  int candidates = 0, near_zero = 0, outside = 0;
  for_rays_leaving_triangles([&](const WatertightRay& r, const Vec3& p0, const Vec3& p1, const Vec3& p2) {
    const ScaledDistance s = scaled_distance(r, p0, p1, p2);
    if (!s.candidate) return;
    ++candidates;
    const float error = near_start_error(s.max_xy, s.max_z, s.abs_det, 0.0f);
    if (std::fabs(s.signed_t) <= error) ++near_zero;
    if (std::fabs((long double)s.signed_t - s.exact_signed_t) > (long double)error) ++outside;
  });
  EXPECT_EQ(outside, 0);
  EXPECT_GT(candidates, 50000);
  EXPECT_GT(near_zero, 0);  // the set reaches the bound's edge
}

// With tnear != 0 the test decides by the sign of T - tnear |det|, computed in float: within the
// bound (with its tnear term) of the same difference computed without rounding, for starts at,
// just around and far from the crossing, before and behind the ray's origin.
TEST(Triangle, NearStartErrorCoversTheComparisonWithTnear) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  int candidates = 0, near_bound = 0, outside = 0;
  for_rays_leaving_triangles([&](const WatertightRay& r, const Vec3& p0, const Vec3& p1, const Vec3& p2) {
    const ScaledDistance s = scaled_distance(r, p0, p1, p2);
    if (!s.candidate || s.abs_det == 0.0f) return;
    ++candidates;
    const float t = float(s.exact_signed_t / s.exact_abs_det);  // the crossing's distance
    const float tnears[] = {t, t * (1.0f + 1e-6f * (2.0f * unit(rng) - 1.0f)), t * 4.0f * unit(rng),
                            -std::fabs(t) * unit(rng), 1e-3f * (2.0f * unit(rng) - 1.0f)};
    for (const float tnear : tnears) {
      if (tnear == 0.0f) continue;
      const float past_start = s.signed_t - tnear * s.abs_det;  // as intersect_triangle computes it
      const long double exact = s.exact_signed_t - (long double)tnear * s.exact_abs_det;
      const float error = near_start_error(s.max_xy, s.max_z, s.abs_det, tnear);
      if (std::fabs(past_start - exact) > (long double)error) ++outside;
      if (std::fabs(past_start) <= error) ++near_bound;
    }
  });
  EXPECT_GT(candidates, 50000);
  EXPECT_GT(near_bound, 1000);  // the starts at the crossing reach the bound's edge
  EXPECT_EQ(outside, 0);
}

// start_side decides a candidate wholly on one side of the ray's origin (across the dominant axis)
// without the error bound. Its argument is independent of the bound's, so the two must never
// disagree: where the bound is sure, it is sure of the same side; the float comparison the test
// would make agrees; and where the ray really crosses the triangle (the edge functions computed
// without rounding share one sign too), the crossing computed without rounding is on that side.
TEST(Triangle, StartSideNeverContradictsTheErrorBound) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  int decided = 0, beyond_the_bound = 0, contradicted = 0, float_disagrees = 0, crossing_disagrees = 0;
  const auto check = [&](const WatertightRay& r, const Vec3& p0, const Vec3& p1, const Vec3& p2) {
    const ScaledDistance s = scaled_distance(r, p0, p1, p2);
    if (!s.candidate) return;
    const float tnears[] = {0.0f, -1e-3f * unit(rng), 1e-3f * unit(rng)};
    for (const float tnear : tnears) {
      const int side = start_side(s.z[0], s.z[1], s.z[2], s.abs_det, tnear);
      if (side == 0) continue;
      ++decided;
      const float past_start = s.signed_t - tnear * s.abs_det;  // as intersect_triangle computes it
      const float error = near_start_error(s.max_xy, s.max_z, s.abs_det, tnear);
      if (side > 0 ? past_start < -error : past_start > error) ++contradicted;
      if (side > 0 ? !(past_start >= 0.0f) : !(past_start <= 0.0f)) ++float_disagrees;
      if (std::fabs(past_start) <= error) ++beyond_the_bound;
      const long double exact = s.exact_signed_t - (long double)tnear * s.exact_abs_det;
      if (s.exact_inside && (side > 0 ? exact <= 0 : exact >= 0)) ++crossing_disagrees;
    }
  };
  for_rays_leaving_triangles(check);
  for_rays_from_afar(check);
  EXPECT_GT(decided, 50000);
  EXPECT_EQ(contradicted, 0);
  EXPECT_EQ(float_disagrees, 0);
  EXPECT_EQ(crossing_disagrees, 0);
  EXPECT_GT(beyond_the_bound, 0);  // and it decides lanes the bound would send to double precision
}
