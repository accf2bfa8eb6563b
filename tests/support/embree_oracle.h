// Embree 3 as an independent oracle (tests) and peer (benchmarks): the same mesh and rays as
// TOYRT, answered by Intel's kernels. Never linked into the shipped module.
#pragma once

#include "core/ray.h"
#include "geometry/mesh.h"

#include <embree3/rtcore.h>

#include <vector>

namespace toyrt::testing {

class EmbreeScene {
 public:
  // robust: RTC_SCENE_FLAG_ROBUST (Embree's watertight-leaning mode); threads 0: all cores;
  // morton: Embree's fast builder (RTC_BUILD_QUALITY_LOW on a RTC_SCENE_FLAG_DYNAMIC scene, its
  // Morton-code build), the peer of TOYRT's LBVH.
  EmbreeScene(const std::vector<Vec3>& vertices, const std::vector<Triangle>& triangles, bool robust = false,
              int threads = 0, bool morton = false);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  Hit intersect(const Ray& ray) const;  // instance is 0 on a hit
  bool occluded(const Ray& ray) const;
  double build_ms() const { return build_ms_; }

 private:
  RTCDevice device_;
  RTCScene scene_;
  double build_ms_ = 0.0;
};

}  // namespace toyrt::testing
