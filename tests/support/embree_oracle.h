// Embree 3 as an independent oracle (tests) and peer (benchmarks): the same mesh and rays as
// TOYRT, answered by Intel's kernels. Never linked into the shipped module.
#pragma once

#include "core/ray.h"
#include "geometry/mesh.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <vector>

namespace toyrt::testing {

class EmbreeScene {
 public:
  // robust: RTC_SCENE_FLAG_ROBUST (Embree's watertight-leaning mode); threads 0: all cores;
  // morton: Embree's fast builder (RTC_BUILD_QUALITY_LOW on a RTC_SCENE_FLAG_DYNAMIC scene, its
  // Morton-code build), the peer of TOYRT's LBVH; count_memory: memory_bytes() counts the device's
  // allocations (Embree's memory monitor, a callback on every one: not for timed builds).
  EmbreeScene(const std::vector<Vec3>& vertices, const std::vector<Triangle>& triangles, bool robust = false,
              int threads = 0, bool morton = false, bool count_memory = false);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  Hit intersect(const Ray& ray) const;  // instance is 0 on a hit
  bool occluded(const Ray& ray) const;
  double build_ms() const { return build_ms_; }
  // Bytes the device holds once the scene is built: the vertex and index buffers and the BVH with
  // its triangle data (as Embree's memory monitor reports its allocations).
  size_t memory_bytes() const { return size_t(std::max<int64_t>(memory_.load(), 0)); }

 private:
  RTCDevice device_;
  RTCScene scene_;
  double build_ms_ = 0.0;
  std::atomic<int64_t> memory_{0};
};

}  // namespace toyrt::testing
