// Builder benchmark: LBVH (OpenCL kernels on PoCL, and the host build a CPU device commits), the
// binned SAH builder and Embree 3 from 10K to 4M triangles: build time, each tree's SAH cost and
// trace speed, and what `auto` would pick for a preview and for a final render, against the best
// total (build + trace) of the two.
// Writes a Markdown report and a CSV for the chart (bench/plot_lbvh.py).
//
//   bench_lbvh [--out FILE.md] [--csv FILE.csv] [--runs N] [--quick]
#include "accel/lbvh_builder.h"
#include "accel/morton_wide_builder.h"
#include "bench_util.h"
#include "core/parallel.h"
#include "embree_oracle.h"
#include "opencl/device.h"
#include "scene/scene.h"
#include "test_scenes.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <functional>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

using namespace toyrt;
using namespace toyrt::testing;
using namespace toyrt::bench;

namespace {

// A mixed set: shadow rays (finite tfar) ask occluded(), the others intersect().
template <class Tracer>
double trace_ms(const Tracer& tracer, const std::vector<Ray>& rays, int runs) {
  return best_ms(runs, [&] {
    for_each_ray(rays, [&](const Ray& ray) {
      if (ray.tfar < kInfinity)
        tracer.occluded(ray);
      else
        tracer.intersect(ray);
    });
  });
}

struct Row {
  size_t triangles;
  double sah_ms, lbvh_ms, lbvh63_ms, embree_ms, host_ms;
  double sah_cost, lbvh_cost, lbvh63_cost;
  double sah_mrays, lbvh_mrays, lbvh63_mrays, embree_mrays, host_mrays;
};

}  // namespace

int main(int argc, char** argv) {
  keep_freed_memory();
  const std::optional<Args> args = parse_args(argc, argv, "[--out FILE.md] [--csv FILE.csv] [--runs N] [--quick]", 3);
  if (!args) return 2;
  const int width = args->quick ? 256 : 512, height = args->quick ? 192 : 384;

  // First use: kernel compilation, reported apart (and out of every build time below).
  double compile_ms = 0.0;
  std::string device;
  {
    const CommitStats warm = compile_lbvh_kernels();
    compile_ms = warm.lbvh_compile_ms;
    if (!warm.warning.empty()) {
      std::fprintf(stderr, "%s\n", warm.warning.c_str());
      return 1;
    }
    device = opencl::device().name;
  }

  std::vector<Row> rows;
  std::vector<std::vector<std::pair<std::string, double>>> stages;
  for (int r : sphere_rings(args->quick)) {
    const MeshData m = uv_sphere(r, r, 1.0f, 0.15f);
    std::fprintf(stderr, "%zu triangles\n", m.triangles.size());
    Row row{};
    row.triangles = m.triangles.size();
    const PrimitiveBounds prims = triangle_bounds(m);
    const std::vector<BBox>& boxes = prims.boxes;
    // Builder alone (what differs between them); the collapse to the wide traversal layout that
    // both then share is not included.
    Bvh sah, lbvh, lbvh63;
    row.sah_ms = best_ms(args->runs, [&] { sah = build_binned_sah(boxes.data(), boxes.size()); });
    LbvhStats st;
    row.lbvh_ms = best_ms(args->runs, [&] { lbvh = build_lbvh(boxes.data(), boxes.size(), {}, &st); });
    stages.push_back(st.stages);
    row.lbvh63_ms =
        best_ms(args->runs, [&] { lbvh63 = build_lbvh(boxes.data(), boxes.size(), LbvhConfig{MortonBits::k63}); });
    row.embree_ms = best_ms(args->runs, [&] { EmbreeScene e(m.vertices, m.triangles); });
    row.host_ms = best_ms(args->runs, [&] { build_morton_wide(boxes.data(), boxes.size(), 8); });
    row.sah_cost = sah.sah_cost();
    row.lbvh_cost = lbvh.sah_cost();
    row.lbvh63_cost = lbvh63.sah_cost();

    const EmbreeScene embree(m.vertices, m.triangles);
    const std::vector<Ray> rays = ray_sets(m, embree, width, height).mixed();
    const auto s_sah = scene_of(m, BuilderKind::Sah, MortonBits::k30);
    const auto s_lbvh = scene_of(m, BuilderKind::Lbvh, MortonBits::k30, LbvhDevice::OpenCl);
    const auto s_host = scene_of(m, BuilderKind::Lbvh, MortonBits::k30, LbvhDevice::Host);
    const auto s_lbvh63 = scene_of(m, BuilderKind::Lbvh, MortonBits::k63);
    row.sah_mrays = rays.size() / trace_ms(*s_sah, rays, args->runs) / 1e3;
    row.lbvh_mrays = rays.size() / trace_ms(*s_lbvh, rays, args->runs) / 1e3;
    row.lbvh63_mrays = rays.size() / trace_ms(*s_lbvh63, rays, args->runs) / 1e3;
    row.embree_mrays = rays.size() / trace_ms(embree, rays, args->runs) / 1e3;
    row.host_mrays = rays.size() / trace_ms(*s_host, rays, args->runs) / 1e3;
    rows.push_back(row);
  }

  // What auto picks, against the better total, for two workloads (rays per pixel: one primary,
  // one shadow, one bounce per sample).
  struct Workload {
    const char* name;
    double rays;
  };
  const Workload workloads[] = {{"preview, 640x360, 1 sample", 640.0 * 360 * 3},
                                {"final, 1920x1080, 64 samples", 1920.0 * 1080 * 64 * 3}};
  const BuilderCostModel model;

  char date[64];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  std::ostringstream md;
  md << "# Builders: the LBVH (on the host and as OpenCL kernels) against SAH and Embree\n\n"
     << "Written by `make bench-lbvh` (`build/bench/bench_lbvh`) on " << date << ": " << cpu_model() << ", "
     << std::thread::hardware_concurrency() << " hardware threads; OpenCL device: " << device << ". Best of "
     << args->runs
     << " runs. Meshes: bumpy UV spheres. Build times are the builders alone (SAH with TBB on all cores, LBVH "
     << "kernels on PoCL on the same cores, Embree's default build with its own TBB), without the collapse to the "
     << "8-wide traversal layout that TOYRT's builders then share; the host LBVH (what a mesh commits on a CPU "
     << "device: build_morton_wide) builds that layout itself, so its time includes it. SAH cost: expected node "
     << "visits plus triangle tests "
     << "of a random ray (traversal and intersection cost 1) of the binary tree. Trace speed: a mixed set of " << width
     << "x" << height << " primary rays, one diffuse bounce and one shadow ray per primary hit, on all threads.\n\n"
     << "Kernel compilation on first use (once per process, not in any build time below): **" << compile_ms
     << " ms**.\n\n"
     << "| triangles | SAH build ms | LBVH build ms | LBVH-63 build ms | Embree build ms | SAH / LBVH build time | "
        "SAH cost: SAH / LBVH / LBVH-63 | Mrays/s: SAH / LBVH / LBVH-63 / Embree | LBVH trace speed vs SAH |\n"
     << "|---|---|---|---|---|---|---|---|---|\n";
  char line[1024];
  for (const Row& r : rows) {
    std::snprintf(
        line, sizeof line,
        "| %zu | %.1f | %.1f | %.1f | %.1f | **%.2fx** | %.1f / %.1f / %.1f | %.2f / %.2f / %.2f / %.2f | %.0f %% |\n",
        r.triangles, r.sah_ms, r.lbvh_ms, r.lbvh63_ms, r.embree_ms, r.sah_ms / r.lbvh_ms, r.sah_cost, r.lbvh_cost,
        r.lbvh63_cost, r.sah_mrays, r.lbvh_mrays, r.lbvh63_mrays, r.embree_mrays, 100.0 * r.lbvh_mrays / r.sah_mrays);
    md << line;
  }
  md << "\nThe kernels' stages at the largest size, the last run (ms): ";
  for (const auto& [name, ms] : stages.back()) {
    std::snprintf(line, sizeof line, "%s %.1f; ", name.c_str(), ms);
    md << line;
  }
  md << "\n\n## The host LBVH\n\nWhat a mesh commits on a CPU device or without OpenCL: sorted Morton codes "
        "built top down straight into wide nodes (no binary tree, no collapse).\n\n"
     << "| triangles | host LBVH build ms (wide nodes included) | kernels' LBVH build ms (binary tree only) | "
        "Mrays/s: host LBVH / kernels' LBVH / SAH |\n|---|---|---|---|\n";
  for (const Row& r : rows) {
    std::snprintf(line, sizeof line, "| %zu | **%.1f** | %.1f | %.2f / %.2f / %.2f |\n", r.triangles, r.host_ms,
                  r.lbvh_ms, r.host_mrays, r.lbvh_mrays, r.sah_mrays);
    md << line;
  }
  md << "\n## What `auto` picks\n\nTotal time = build + rays / measured trace speed, per mesh and workload, "
        "the LBVH's being the host build's (what a commit on this machine runs); `auto` decides from its cost "
        "model (native/accel/builder.h) before building anything.\n\n"
     << "| triangles | workload | rays | SAH total s | LBVH total s | auto picks | auto's total vs the better |\n"
     << "|---|---|---|---|---|---|---|\n";
  for (const Row& r : rows)
    for (const Workload& w : workloads) {
      const double sah = r.sah_ms / 1e3 + w.rays / (r.sah_mrays * 1e6);
      const double lbvh = r.host_ms / 1e3 + w.rays / (r.host_mrays * 1e6);
      const BuilderKind pick = model.choose(r.triangles, w.rays);
      const double picked = pick == BuilderKind::Lbvh ? lbvh : sah;
      std::snprintf(line, sizeof line, "| %zu | %s | %.3g | %.3f | %.3f | %s | %+.1f %% |\n", r.triangles, w.name,
                    w.rays, sah, lbvh, pick == BuilderKind::Lbvh ? "LBVH" : "SAH",
                    100.0 * (picked / std::min(sah, lbvh) - 1.0));
      md << line;
    }
  md << "\n![build time and trace speed against triangle count](lbvh.png)\n";
  std::cout << md.str();
  if (!args->out.empty()) std::ofstream(args->out) << md.str();
  if (!args->csv.empty()) {
    std::ofstream csv(args->csv);
    csv << "triangles,sah_ms,lbvh_ms,lbvh63_ms,embree_ms,sah_cost,lbvh_cost,lbvh63_cost,sah_mrays,lbvh_mrays,lbvh63_"
           "mrays,embree_mrays,host_ms,host_mrays\n";
    for (const Row& r : rows)
      csv << r.triangles << ',' << r.sah_ms << ',' << r.lbvh_ms << ',' << r.lbvh63_ms << ',' << r.embree_ms << ','
          << r.sah_cost << ',' << r.lbvh_cost << ',' << r.lbvh63_cost << ',' << r.sah_mrays << ',' << r.lbvh_mrays
          << ',' << r.lbvh63_mrays << ',' << r.embree_mrays << ',' << r.host_ms << ',' << r.host_mrays << '\n';
  }
  return 0;
}
