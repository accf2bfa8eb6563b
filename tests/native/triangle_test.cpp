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
