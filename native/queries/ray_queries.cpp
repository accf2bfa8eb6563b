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
  // Scenes that fit the caches walk one ray at a time; larger ones interleave the rays' walks
  // (queries/interleaved_walk.h: 1.3x at 82K triangles, 1.9x at 5.2M).
  const bool interleave = interleaving_pays(scene);
  run_with_threads(threads, [&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.count, kRayGrain), [&](const tbb::blocked_range<size_t>& r) {
      if (interleave) {
        std::fill(counts + r.begin(), counts + r.end(), 0u);
        for_each_crossing_of_rays(scene, rays, r.begin(), r.end(),
                                  [&](uint32_t i, uint32_t, uint32_t, uint32_t, const Crossing&) { ++counts[i]; });
        return;
      }
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
  const bool interleave = interleaving_pays(scene);
  run_with_threads(threads, [&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.count, kRayGrain), [&](const tbb::blocked_range<size_t>& r) {
      struct Entry {
        uint32_t ray;
        double t;
        int32_t instance, mesh, prim;
        float u, v;
      };
      // The same walks as the count: the same crossings, in a traversal order made canonical here.
      const auto write_ray = [&](size_t i, Entry* first, Entry* last) {
        std::sort(first, last, [](const Entry& a, const Entry& b) {
          if (a.t != b.t) return a.t < b.t;
          if (a.instance != b.instance) return a.instance < b.instance;
          return a.prim < b.prim;
        });
        const Ray ray = rays.at(i);
        size_t k = size_t(out.offsets[i]);
        for (const Entry* e = first; e != last; ++e, ++k) {
          out.ray[k] = uint32_t(i);
          out.t[k] = reported_t(e->t, ray.tnear, ray.tfar);
          out.u[k] = e->u;
          out.v[k] = e->v;
          out.mesh[k] = e->mesh;
          out.instance[k] = e->instance;
          out.prim[k] = e->prim;
        }
      };
      std::vector<Entry> entries;  // one per task, reused by its rays
      if (!interleave) {
        for (size_t i = r.begin(); i != r.end(); ++i) {
          entries.clear();
          for_each_crossing(scene, rays.at(i), [&](uint32_t instance, uint32_t mesh, uint32_t prim, const Crossing& c) {
            entries.push_back(
                {uint32_t(i), c.t, int32_t(instance), int32_t(mesh), int32_t(prim), float(c.u), float(c.v)});
          });
          write_ray(i, entries.data(), entries.data() + entries.size());
        }
        return;
      }
      // The rays' crossings come mixed: each is placed in its ray's range (known from the counts).
      const int64_t base = out.offsets[r.begin()];
      entries.resize(size_t(out.offsets[r.end()] - base));
      std::vector<int64_t> next(out.offsets.begin() + int64_t(r.begin()), out.offsets.begin() + int64_t(r.end()));
      for_each_crossing_of_rays(scene, rays, r.begin(), r.end(),
                                [&](uint32_t i, uint32_t instance, uint32_t mesh, uint32_t prim, const Crossing& c) {
                                  entries[size_t(next[i - r.begin()]++ - base)] = {
                                      i, c.t, int32_t(instance), int32_t(mesh), int32_t(prim), float(c.u), float(c.v)};
                                });
      for (size_t i = r.begin(); i != r.end(); ++i)
        write_ray(i, entries.data() + (out.offsets[i] - base), entries.data() + (out.offsets[i + 1] - base));
    });
  });
  return out;
}

}  // namespace toyrt::queries
