// The slab test: NaN safety for axis-parallel rays and conservative far distances.
#include "core/bbox.h"

#include <gtest/gtest.h>

using namespace toyrt;

namespace {
const float kUnitBox[6] = {0, 0, 0, 1, 1, 1};
float entry(const Vec3& o, const Vec3& d, float tnear = 0.0f, float tfar = kInfinity) {
  return intersect_box(make_ray_box_data(o, d), kUnitBox, tnear, tfar);
}
}  // namespace

TEST(BoxTest, EntryDistanceOfAStraightHit) {
  EXPECT_FLOAT_EQ(entry({0.5f, 0.5f, 3.0f}, {0, 0, -1}), 2.0f);
  EXPECT_EQ(entry({0.5f, 0.5f, 0.5f}, {0, 0, -1}), 0.0f);  // inside: enters at tnear
}

TEST(BoxTest, RayInsideASlabPlaneIsInsideThatSlab) {
  // Direction components of +0 and -0 make 0 * inf = NaN on the planes the origin lies on.
  for (float x : {0.0f, 1.0f})
    for (float zero : {0.0f, -0.0f}) {
      EXPECT_NE(entry({x, 0.5f, 3.0f}, {zero, zero, -1}), kInfinity) << "x=" << x;
      EXPECT_NE(entry({x, 1.0f, 3.0f}, {zero, zero, -1}), kInfinity) << "x=" << x;
      EXPECT_NE(entry({-1.0f, x, x}, {1, zero, zero}), kInfinity) << "x=" << x;
    }
}

TEST(BoxTest, AxisParallelRayOutsideASlabMisses) {
  EXPECT_EQ(entry({1.0001f, 0.5f, 3.0f}, {0, 0, -1}), kInfinity);
  EXPECT_EQ(entry({-0.0001f, 0.5f, 3.0f}, {-0.0f, 0, -1}), kInfinity);
}

TEST(BoxTest, RespectsTheSegment) {
  EXPECT_EQ(entry({0.5f, 0.5f, 3.0f}, {0, 0, -1}, 0.0f, 1.5f), kInfinity);  // ends before the box
  EXPECT_EQ(entry({0.5f, 0.5f, 3.0f}, {0, 0, 1}), kInfinity);               // box behind
  EXPECT_NE(entry({0.5f, 0.5f, 3.0f}, {0, 0, -1}, 0.0f, 2.0f), kInfinity);  // touches at tfar
}

TEST(BoxTest, GrazingACornerStillEnters) {
  // A ray through the box's corner exactly, from a direction not aligned with any axis.
  const Vec3 corner(1, 1, 1), org = corner + Vec3(0.3f, 0.7f, 0.11f);
  EXPECT_NE(entry(org, corner - org), kInfinity);
}
