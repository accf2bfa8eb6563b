// The lamps a ray can see, found through a BVH over their emitting shapes instead of by testing
// every lamp: the integrator asks for the lamps along every camera and specular ray
// (render/visible_lights.h), so with thousands of lamps that loop cost more than the rest of the
// ray. Built at commit from kLampBvhFrom lamps (the light tree's boxes, lights/light_bounds.h:
// every point that emits); lamps at infinity (suns) have no box and are listed apart, since every
// ray that leaves the scene sees them.
#pragma once

#include "accel/bvh.h"
#include "accel/traverse.h"
#include "lights/light.h"

#include <cstdint>
#include <vector>

namespace toyrt {

// From this many lamps a scene builds the BVH; below, the loop over every lamp is as fast (a few
// box tests against a few lamp tests) and builds nothing.
inline constexpr size_t kLampBvhFrom = 16;

struct LampBvh {
  Bvh bvh;                            // over the lamps with a box; prim_ids are lamp indices
  std::vector<uint32_t> at_infinity;  // the lamps without one
  bool empty() const { return bvh.empty() && at_infinity.empty(); }
  size_t memory_bytes() const;
};

LampBvh build_lamp_bvh(const std::vector<Light>& lights);

// Calls visit(j) for every lamp j whose box the ray org + t dir crosses for t in [from, limit],
// then, when `escaped` (the ray left the scene), for every lamp at infinity. A superset of the
// lamps the ray sees: the caller tests each one.
template <class Visit>
void for_lamps_along(const LampBvh& lamps, const Vec3& org, const Vec3& dir, float from, float limit, bool escaped,
                     Visit&& visit) {
  if (!lamps.bvh.empty()) {
    float tfar = limit;
    traverse<false>(lamps.bvh, make_ray_box_data(org, dir), from, tfar, [&](uint32_t first, uint32_t count, float&) {
      for (uint32_t k = first; k < first + count; ++k) visit(size_t(lamps.bvh.prim_ids[k]));
      return false;  // lamps are not surfaces: every one along the ray counts, none shortens it
    });
  }
  if (escaped)
    for (const uint32_t j : lamps.at_infinity) visit(size_t(j));
}

}  // namespace toyrt
