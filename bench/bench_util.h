// The benchmarks' kit: timing, the machine's description, and the setup every bench repeats
// (a committed one-instance scene per builder, the LBVH kernels compiled outside every timing,
// the light and the primary / diffuse / shadow ray sets traced from Embree's hits, a parallel
// loop over rays). One definition, so the benches measure the same things the same way.
#pragma once

#include "embree_oracle.h"
#include "scene/scene.h"
#include "test_scenes.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <malloc.h>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace toyrt::bench {

// Best wall time of `runs` calls, in milliseconds: the least disturbed run on a shared machine.
inline double best_ms(int runs, const std::function<void()>& f) {
  double best = 1e300;
  for (int i = 0; i < runs; ++i) {
    const auto start = std::chrono::steady_clock::now();
    f();
    best = std::min(best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
  return best;
}

using Clock = std::chrono::steady_clock;
inline double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}
// Warm builds for every engine, on purpose: glibc returns large freed blocks to the kernel
// (mmap'd ones at once, the heap's top past 128 KB), so an engine that takes its build memory
// through malloc pays the kernel's zeroing of fresh pages on every build, or not, depending on
// what the process freed before (docs/trace-speed.md, thirty-third session: Embree's Morton build
// at 1M took 35-46 ms inside bench_trace's sequence and 42-72 ms elsewhere). Blocks up to 32 MB
// (glibc's largest mmap threshold) come from the heap and freed memory stays in it, so each timed
// build reuses what the warm-up build touched, as TOYRT's own pool (core/huge_page_pool.h) does.
// Called first thing by the programs that time builds.
inline void keep_freed_memory() {
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
}

inline double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

inline std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown CPU";
}

// The benches' command line: each bench accepts the options its usage line names, out of
// --out FILE, --csv FILE, --dump DIR, --runs N (at least 1; `runs` when absent), --quick and
// --smoke. Anything else prints the usage and returns nothing.
struct Args {
  std::string out, csv, dump;
  std::string only;  // --only TEXT: the cases whose name contains TEXT (benches that accept it)
  int runs = 1;
  bool quick = false, smoke = false;
};

inline std::optional<Args> parse_args(int argc, char** argv, const std::string& usage, int runs = 1) {
  Args args;
  args.runs = runs;
  auto accepts = [&](const char* flag) { return usage.find(flag) != std::string::npos; };
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    const bool has_value = i + 1 < argc;
    if (flag == "--out" && has_value && accepts("--out"))
      args.out = argv[++i];
    else if (flag == "--csv" && has_value && accepts("--csv"))
      args.csv = argv[++i];
    else if (flag == "--dump" && has_value && accepts("--dump"))
      args.dump = argv[++i];
    else if (flag == "--only" && has_value && accepts("--only"))
      args.only = argv[++i];
    else if (flag == "--runs" && has_value && accepts("--runs"))
      args.runs = std::max(1, std::atoi(argv[++i]));
    else if (flag == "--quick" && accepts("--quick"))
      args.quick = true;
    else if (flag == "--smoke" && accepts("--smoke"))
      args.smoke = true;
    else {
      std::fprintf(stderr, "usage: %s %s\n", argv[0], usage.c_str());
      return std::nullopt;
    }
  }
  return args;
}

// The builder benches' size sweep: bumpy UV spheres of r x r quads, 2 r^2 triangles: 10K, 100K,
// 1M, 4M (quick: the first two).
inline std::vector<int> sphere_rings(bool quick) {
  return quick ? std::vector<int>{71, 224} : std::vector<int>{71, 224, 708, 1415};
}

// The mesh in a scene of its own (one identity instance), committed with `kind` (an LBVH with
// `bits`, built where `device` says).
inline std::unique_ptr<Scene> scene_of(const testing::MeshData& m, BuilderKind kind = BuilderKind::Sah,
                                       MortonBits bits = MortonBits::k30, LbvhDevice device = LbvhDevice::Auto) {
  auto s = std::make_unique<Scene>();
  s->add_instance(s->add_mesh(m.vertices, m.triangles), Mat4(1.0f));
  CommitOptions o;
  o.builder = kind;
  o.lbvh.bits = bits;
  o.lbvh.device = device;
  s->commit(o);
  return s;
}

// Compiles the LBVH kernels once (the first LBVH build of the process, for each key width), so
// that no timing includes it; returns the commits' stats (lbvh_compile_ms of both, and a warning
// when OpenCL is absent).
inline CommitStats compile_lbvh_kernels() {
  CommitStats stats = scene_of(testing::uv_sphere(10, 10), BuilderKind::Lbvh, MortonBits::k63)->commit_stats();
  const CommitStats narrow =
      scene_of(testing::uv_sphere(10, 10), BuilderKind::Lbvh, MortonBits::k30, LbvhDevice::OpenCl)->commit_stats();
  stats.lbvh_compile_ms += narrow.lbvh_compile_ms;
  return stats;
}

// The benches' light: above and beside the mesh's box, at a distance of its diagonal.
inline Vec3 light_for(const BBox& box) { return box.center() + glm::length(box.extent()) * Vec3(-0.4f, -0.9f, 1.3f); }

// Primary rays at the mesh's box, and from each primary hit (found by Embree) one diffuse bounce
// and one shadow ray to light_for(box).
struct RaySets {
  std::vector<Ray> primary, diffuse, shadow;
  // All three in that order.
  std::vector<Ray> mixed() const {
    std::vector<Ray> rays = primary;
    rays.insert(rays.end(), diffuse.begin(), diffuse.end());
    rays.insert(rays.end(), shadow.begin(), shadow.end());
    return rays;
  }
};

inline RaySets ray_sets(const testing::MeshData& m, const testing::EmbreeScene& embree, int width, int height) {
  RaySets sets;
  const BBox box = testing::bounds_of(m);
  sets.primary = testing::primary_rays(box, width, height);
  std::vector<Hit> hits;
  for (const Ray& ray : sets.primary) hits.push_back(embree.intersect(ray));
  sets.diffuse = testing::diffuse_rays(m, sets.primary, hits, 3);
  sets.shadow = testing::shadow_rays(m, sets.primary, hits, light_for(box));
  return sets;
}

// f(ray) for every ray, on all threads, in chunks of 256 rays.
template <class F>
void for_each_ray(const std::vector<Ray>& rays, const F& f) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) f(rays[i]);
  });
}

}  // namespace toyrt::bench
