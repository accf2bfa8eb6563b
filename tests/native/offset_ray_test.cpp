// The self-intersection-safe origin: rays leaving a surface from the offset origin never hit
// the surface they leave, at any scale or distance from the origin, and the offset stays small.
#include "geometry/offset_ray.h"
#include "scene/scene.h"

#include <gtest/gtest.h>

#include <random>

using namespace toyrt;

TEST(OffsetRayOrigin, LeavingRaysNeverHitTheirOwnSurface) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f), sym(-1.0f, 1.0f);
  for (float scale : {1e-4f, 1e-2f, 1.0f, 1e2f, 1e4f})
    for (float distance : {0.0f, 1.0f, 1e3f, 1e5f, 1e6f}) {
      if (scale < 1e-5f * distance) continue;  // the triangle would be smaller than the float spacing
      // One large tilted triangle of size `scale`, `distance` from the origin.
      const Vec3 c = distance * glm::normalize(Vec3(1.0f, -0.7f, 0.4f));
      const Vec3 p0 = c + scale * Vec3(-1.0f, -1.0f, 0.1f), p1 = c + scale * Vec3(1.3f, -0.9f, -0.2f),
                 p2 = c + scale * Vec3(0.1f, 1.2f, 0.3f);
      Scene scene;
      scene.add_instance(scene.add_mesh({p0, p1, p2}, {{0, 1, 2}}), Mat4(1.0f));
      scene.commit();
      const Vec3 n = glm::normalize(glm::cross(p1 - p0, p2 - p0));
      int self_hits = 0, naive_self_hits = 0;
      for (int i = 0; i < 2000; ++i) {
        float a = unit(rng), b = unit(rng);
        if (a + b > 1.0f) a = 1.0f - a, b = 1.0f - b;
        const Vec3 p = (1.0f - a - b) * p0 + a * p1 + b * p2;
        const float side = i % 2 ? 1.0f : -1.0f;  // leave on either face
        Vec3 d = glm::normalize(Vec3(sym(rng), sym(rng), sym(rng)));
        if (glm::dot(d, side * n) < 0.0f) d = -d;
        self_hits += scene.occluded(Ray{offset_ray_origin(p, side * n), 0.0f, d, kInfinity});
        naive_self_hits += scene.occluded(Ray{p, 0.0f, d, kInfinity});
        // The offset moves the point by a few hundred ulps at most.
        const Vec3 moved = offset_ray_origin(p, side * n) - p;
        EXPECT_LE(glm::length(moved), 1e-4f + 1e-4f * glm::length(p));
      }
      EXPECT_EQ(self_hits, 0) << "scale " << scale << " distance " << distance;
      if (distance >= 1e3f) {
        EXPECT_GT(naive_self_hits, 0) << "the case should be hard without the offset";
      }
    }
}
