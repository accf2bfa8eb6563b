#include "embree_oracle.h"

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

namespace toyrt::testing {

EmbreeScene::EmbreeScene(const std::vector<Vec3>& vertices, const std::vector<Triangle>& triangles, bool robust,
                         int threads, bool morton, bool count_memory) {
  std::string config = threads > 0 ? "threads=" + std::to_string(threads) : "";
  // TOYRT_EMBREE_CONFIG: more of Embree's device settings, for a look inside (verbose=2 prints
  // its tree's statistics: bench/trace_only.cpp's `wide` mode sets TOYRT's beside them).
  if (const char* more = std::getenv("TOYRT_EMBREE_CONFIG")) config += (config.empty() ? "" : ",") + std::string(more);
  device_ = rtcNewDevice(config.c_str());
  if (!device_) throw std::runtime_error("Embree: cannot create a device");
  // Counts every allocation and release (from any of the build's threads).
  if (count_memory)
    rtcSetDeviceMemoryMonitorFunction(
        device_,
        [](void* counter, ssize_t bytes, bool) {
          static_cast<std::atomic<int64_t>*>(counter)->fetch_add(int64_t(bytes), std::memory_order_relaxed);
          return true;
        },
        &memory_);
  const auto start = std::chrono::steady_clock::now();
  scene_ = rtcNewScene(device_);
  rtcSetSceneFlags(scene_, RTCSceneFlags((robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE) |
                                         (morton ? RTC_SCENE_FLAG_DYNAMIC : RTC_SCENE_FLAG_NONE)));
  if (morton) rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_LOW);
  RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  if (morton) rtcSetGeometryBuildQuality(geom, RTC_BUILD_QUALITY_LOW);
  auto* vb = static_cast<float*>(
      rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertices.size()));
  auto* ib = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                            3 * sizeof(uint32_t), triangles.size()));
  std::memcpy(vb, vertices.data(), vertices.size() * sizeof(Vec3));
  std::memcpy(ib, triangles.data(), triangles.size() * sizeof(Triangle));
  rtcCommitGeometry(geom);
  rtcAttachGeometry(scene_, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(scene_);
  build_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

EmbreeScene::~EmbreeScene() {
  rtcReleaseScene(scene_);
  rtcReleaseDevice(device_);
}

namespace {
void fill(RTCRay& r, const Ray& ray) {
  r.org_x = ray.org.x;
  r.org_y = ray.org.y;
  r.org_z = ray.org.z;
  r.dir_x = ray.dir.x;
  r.dir_y = ray.dir.y;
  r.dir_z = ray.dir.z;
  r.tnear = ray.tnear;
  r.tfar = ray.tfar;
  r.time = 0.0f;
  r.mask = 0xFFFFFFFFu;
  r.id = 0;
  r.flags = 0;
}
}  // namespace

Hit EmbreeScene::intersect(const Ray& ray) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  fill(rh.ray, ray);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene_, &context, &rh);
  Hit hit;
  if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
    hit.t = rh.ray.tfar;
    hit.u = rh.hit.u;
    hit.v = rh.hit.v;
    hit.prim = int32_t(rh.hit.primID);
    hit.instance = 0;
  }
  return hit;
}

bool EmbreeScene::occluded(const Ray& ray) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay r;
  fill(r, ray);
  rtcOccluded1(scene_, &context, &r);
  return r.tfar < 0.0f;  // Embree sets tfar to -inf on an occlusion
}

}  // namespace toyrt::testing
