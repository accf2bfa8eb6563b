// The lamp BVH (lights/lamp_bvh.h) against the loop over every lamp it replaces for the rays that
// see lamps: every lamp a ray hits within its segment is visited (a superset: the caller tests
// each), suns only by rays that leave the scene, and far fewer lamps than all are visited.
#include "lights/lamp_bvh.h"
#include "sampling/rng.h"
#include "sampling/warp.h"

#include "light_estimates.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <vector>

using namespace toyrt;
using namespace toyrt::testing;

namespace {

// Round lamps large enough for rays to hit them often, beside the mixed set's point lamps, spots,
// rectangles and suns.
std::vector<Light> lamps_to_see(uint32_t seed) {
  std::vector<Light> lights = mixed_lights(400, seed);
  for (uint32_t i = 0; i < 200; ++i) {
    const auto r = [&](uint32_t d) { return random_float(i, 7, d, seed); };
    const Vec3 pos(20.0f * r(0) - 10.0f, 20.0f * r(1) - 10.0f, 4.0f * r(2) - 2.0f);
    lights.emplace_back(PointLight::make(pos, 10.0f, Vec3(1.0f), 0.2f + 0.8f * r(3)));
  }
  return lights;
}

}  // namespace

TEST(LampBvh, EveryLampARaySeesWithinItsSegmentIsVisited) {
  const std::vector<Light> lights = lamps_to_see(3);
  const LampBvh lamps = build_lamp_bvh(lights);
  ASSERT_EQ(lamps.at_infinity.size(), 2u);  // the two suns
  constexpr float kAtInfinity = std::numeric_limits<float>::max();
  size_t seen = 0, visited_total = 0;
  const uint32_t rays = 20000;
  for (uint32_t i = 0; i < rays; ++i) {
    const auto r = [&](uint32_t d) { return random_float(i, 1, d, 11); };
    const Vec3 org(24.0f * r(0) - 12.0f, 24.0f * r(1) - 12.0f, 10.0f * r(2) - 5.0f);
    const Vec3 dir = sample_uniform_sphere(Vec2(r(3), r(4)));
    const bool escaped = r(5) < 0.5f;
    const float from = r(6) < 0.5f ? 0.0f : 2.0f * r(7);
    const float limit = escaped ? kInfinity : from + 20.0f * r(8);
    std::vector<char> visited(lights.size(), 0);
    for_lamps_along(lamps, org, dir, from, limit, escaped, [&](size_t j) { visited[j] = 1; });
    for (size_t j = 0; j < lights.size(); ++j) {
      const LightEval e = evaluate_light(lights[j], org, dir, AreaSampling::SolidAngle);
      if (!e.hit()) continue;
      const bool within = e.distance == kAtInfinity ? escaped : e.distance >= from && e.distance < limit;
      if (!within) continue;
      ++seen;
      ASSERT_TRUE(visited[j]) << "ray " << i << " sees lamp " << j << " at " << e.distance << " unvisited";
    }
    visited_total += size_t(std::count(visited.begin(), visited.end(), 1));
  }
  EXPECT_GT(seen, size_t(rays) / 4);  // the rays do see lamps: the check has something to check
  // It prunes: a ray visits a few per cent of the 602 lamps, not all of them.
  EXPECT_LT(double(visited_total) / rays, 0.1 * double(lights.size()));
}

TEST(LampBvh, SunsAreVisitedOnlyByRaysThatLeaveTheScene) {
  const std::vector<Light> lights = lamps_to_see(5);
  const LampBvh lamps = build_lamp_bvh(lights);
  for (const bool escaped : {false, true}) {
    size_t suns = 0;
    for_lamps_along(lamps, Vec3(0.0f, 0.0f, 50.0f), Vec3(0.0f, 0.0f, 1.0f), 0.0f, escaped ? kInfinity : 5.0f, escaped,
                    [&](size_t j) { suns += std::holds_alternative<SunLight>(lights[j]); });
    EXPECT_EQ(suns, escaped ? 2u : 0u);
  }
}
