#include "queries/ray_queries.h"

#include "core/parallel.h"
#include "queries/crossing_walk.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

namespace toyrt::queries {
namespace {

// Rays per task, as in the nearest-hit batch: every ray here walks its whole length, so smaller
// grains balance better than there.
constexpr size_t kRayGrain = 64;

// The float the API reports for a crossing's double t: rounded, then kept inside [tnear, tfar)
// (rounding may land a t just below tfar onto it).
float reported_t(double t, float tnear, float tfar) {
  float f = float(t);
  if (!(f < tfar)) f = std::nextafter(tfar, -kInfinity);
  return std::max(f, tnear);
}

}  // namespace

void count_intersections(const Scene& scene, const RayBatch& rays, uint32_t* counts, int threads) {
  scene.check_committed();
  check_threads(threads);
  run_with_threads(threads, [&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.count, kRayGrain), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i) {
        uint32_t n = 0;
        for_each_crossing(scene, rays.at(i), [&](uint32_t, uint32_t, uint32_t, const Crossing&) { ++n; });
        counts[i] = n;
      }
    });
  });
}

HitList list_intersections(const Scene& scene, const RayBatch& rays, size_t max_hits, int threads) {
  // Counted first, so the bound is checked before anything of the answer's size is allocated.
  std::vector<uint32_t> counts(rays.count);
  count_intersections(scene, rays, counts.data(), threads);
  HitList out;
  out.offsets.resize(rays.count + 1);
  out.offsets[0] = 0;
  for (size_t i = 0; i < rays.count; ++i) out.offsets[i + 1] = out.offsets[i] + int64_t(counts[i]);
  const size_t total = size_t(out.offsets[rays.count]);
  if (total > max_hits)
    throw std::length_error("list_intersections would return " + std::to_string(total) + " hits, more than max_hits=" +
                            std::to_string(max_hits) + ": split the rays or raise max_hits");
  out.ray.resize(total);
  out.t.resize(total);
  out.u.resize(total);
  out.v.resize(total);
  out.mesh.resize(total);
  out.instance.resize(total);
  out.prim.resize(total);
  run_with_threads(threads, [&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.count, kRayGrain), [&](const tbb::blocked_range<size_t>& r) {
      struct Entry {
        double t;
        int32_t instance, mesh, prim;
        float u, v;
      };
      std::vector<Entry> entries;  // one per task, reused by its rays
      for (size_t i = r.begin(); i != r.end(); ++i) {
        const Ray ray = rays.at(i);
        entries.clear();
        for_each_crossing(scene, ray, [&](uint32_t instance, uint32_t mesh, uint32_t prim, const Crossing& c) {
          entries.push_back({c.t, int32_t(instance), int32_t(mesh), int32_t(prim), float(c.u), float(c.v)});
        });
        // The same walk as the count: the same crossings, in a traversal order made canonical here.
        std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
          if (a.t != b.t) return a.t < b.t;
          if (a.instance != b.instance) return a.instance < b.instance;
          return a.prim < b.prim;
        });
        size_t k = size_t(out.offsets[i]);
        for (const Entry& e : entries) {
          out.ray[k] = uint32_t(i);
          out.t[k] = reported_t(e.t, ray.tnear, ray.tfar);
          out.u[k] = e.u;
          out.v[k] = e.v;
          out.mesh[k] = e.mesh;
          out.instance[k] = e.instance;
          out.prim[k] = e.prim;
          ++k;
        }
      }
    });
  });
  return out;
}

}  // namespace toyrt::queries
