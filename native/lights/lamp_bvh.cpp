#include "lights/lamp_bvh.h"

#include "accel/builder.h"

namespace toyrt {

LampBvh build_lamp_bvh(const std::vector<Light>& lights) {
  LampBvh lamps;
  std::vector<BBox> boxes;
  std::vector<uint32_t> boxed;
  for (size_t j = 0; j < lights.size(); ++j) {
    BBox box = light_bounds(lights[j]).box;
    if (box.empty()) {
      lamps.at_infinity.push_back(uint32_t(j));
      continue;
    }
    // The shapes' points are computed in float from the same values the lamp tests use; a few
    // ulps of padding keep every point the test can hit inside the box.
    const Vec3 pad = (glm::abs(box.lo) + glm::abs(box.hi)) * (4.0f * gamma(4));
    box.lo -= pad;
    box.hi += pad;
    boxes.push_back(box);
    boxed.push_back(uint32_t(j));
  }
  if (boxes.empty()) return lamps;
  BuildConfig config;
  config.sah.max_leaf = 2;  // a lamp test is cheap, but not cheaper than a box test
  lamps.bvh = build_bvh(BuilderKind::Sah, boxes.data(), boxes.size(), config);
  for (uint32_t& id : lamps.bvh.prim_ids) id = boxed[id];
  return lamps;
}

size_t LampBvh::memory_bytes() const {
  return bvh.nodes.capacity() * sizeof(Node) + bvh.prim_ids.capacity() * sizeof(uint32_t) +
         at_infinity.capacity() * sizeof(uint32_t);
}

}  // namespace toyrt
