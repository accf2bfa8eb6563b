// TOYRT alone tracing one ray set on one thread, for profilers: `perf record`, or
// `valgrind --tool=cachegrind`, whose instruction counts are the one measure this shared machine
// does not blur (bench_trace gives the speed against Embree). Prints rays, hits and a checksum of
// the distances, so an A/B of two builds also shows that both found the same hits.
//
//   trace_only [primary|diffuse|shadow] [rings] [repeats] [embree] [room|soup]   (rings 708: the
//                                         1M-triangle sphere; room: traced inside a closed room, see
//                                         below; soup: bench_trace's triangle soup of rings x 1000;
//                                         embree: the same rays through Embree; words in any order;
//                                         TOYRT_FRAME=1024x768: bench_trace's camera frame instead
//                                         of 320x240, whose neighbouring rays share more lines)
//   trace_only commit [rings] [repeats]   the whole single-thread SAH commit of a fresh scene, in
//                                         CPU milliseconds (the process's CPU clock: one thread,
//                                         so other work on the machine does not inflate it)
//   trace_only commit-all [rings] [repeats]   the same on every core, in wall-clock milliseconds
//   trace_only lbvh-commit [rings] [repeats]  the whole LBVH commit on every core, wall-clock ms
//   trace_only commit[-all] N [repeats] soup  the same over bench_trace's triangle soup of N x 1000
//   trace_only lbvh-all [rings] [repeats]     the whole LBVH commit on every core against Embree's
//                                             Morton build (LOW quality, dynamic scene), interleaved,
//                                             wall-clock medians, with the LBVH's stage times
//   trace_only sah-all [rings] [repeats] [soup]   the whole SAH commit against Embree's default
//                                             build, both on every core, interleaved, wall ms
//                                             (lbvh-all and sah-all: TOYRT_THREADS=N runs both
//                                             engines on N threads, as bench_trace's rows;
//                                             TOYRT_IDLE_US=N sleeps N us before each timed one)
//   trace_only wide [rings] [repeats] [soup]   the 8-wide layout of the SAH and LBVH trees, collapsed
//                             greedily and by the SAH dynamic programme: children a node, SAH cost,
//                             collapse ms, and the cost on Embree's own metric (below), to set beside
//                             the figure Embree prints for its tree with
//                             `TOYRT_EMBREE_CONFIG=verbose=2 trace_only shadow [rings] 1 embree`
#include "accel/binned_sah_builder.h"
#include "accel/lbvh_builder.h"
#include "accel/morton_wide_builder.h"
#include "accel/wide_bvh.h"
#include "bench_util.h"
#include "embree_oracle.h"
#include "geometry/triangle_block.h"
#include "scene/scene.h"
#include "test_scenes.h"

#include <unistd.h>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

using namespace toyrt;
using namespace toyrt::testing;

namespace {

// A wide tree's expected cost on the metric Embree's statistics print (verbose=2): the areas of
// every node's box and of every leaf's box times its 4-triangle blocks, over the root's. TOYRT's
// leaves are tested eight triangles at a time, so its blocks term is given too.
struct EmbreeMetric {
  double nodes = 1.0;  // the root
  double blocks_of_4 = 0.0, blocks_of_8 = 0.0;
  double triangles_a_leaf = 0.0;
};
EmbreeMetric embree_metric(const WideBvh& wide) {
  EmbreeMetric m;
  if (wide.nodes.empty()) return m;
  BBox root;
  for (int i = 0; i < kWidth; ++i)
    if (wide.nodes[0].used(i)) root.extend(wide.nodes[0].box(i));
  size_t leaves = 0, triangles = 0;
  for (const WideNode& n : wide.nodes)
    for (int i = 0; i < kWidth; ++i) {
      if (!n.used(i)) continue;
      const double p = double(n.box(i).half_area()) / double(root.half_area());
      if (n.count[i] == 0) {
        m.nodes += p;
        continue;
      }
      m.blocks_of_4 += p * double((n.count[i] + 3) / 4);
      m.blocks_of_8 += p * double((n.count[i] + kBlockWidth - 1) / kBlockWidth);
      ++leaves;
      triangles += n.count[i];
    }
  m.triangles_a_leaf = double(triangles) / double(leaves);
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  bench::keep_freed_memory();
  const std::string kind = argc > 1 ? argv[1] : "diffuse";
  const int rings = argc > 2 ? std::atoi(argv[2]) : 224;
  const int repeats = argc > 3 ? std::atoi(argv[3]) : 1;
  // The words after the repeats, in any order: room, soup, embree (below).
  auto word = [&](const char* w) {
    return std::find(argv + std::min(argc, 4), argv + argc, std::string(w)) != argv + argc;
  };
  const bool room = word("room");
  // "soup" (commit, commit-all, sah-all and the ray sets): bench_trace's triangle soup of
  // `rings` x 1000 triangles instead of the sphere.
  const bool soup = word("soup");
  const MeshData mesh = soup ? triangle_soup(size_t(rings) * 1000, 0.02f, 1) : uv_sphere(rings, rings, 1.0f, 0.15f);
  if (kind == "lbvh-all" || kind == "sah-all") {
    const bool sah = kind == "sah-all";
    const int threads = std::getenv("TOYRT_THREADS") ? std::atoi(std::getenv("TOYRT_THREADS")) : 0;
    // TOYRT_IDLE_US=N: each engine's timed operation follows N microseconds asleep, so that it
    // finds TBB's workers asleep, as a commit after a user's export does (docs/trace-speed.md,
    // thirty-seventh session).
    const int idle_us = std::getenv("TOYRT_IDLE_US") ? std::atoi(std::getenv("TOYRT_IDLE_US")) : 0;
    auto wall_ms = [] {
      timespec ts;
      clock_gettime(CLOCK_MONOTONIC, &ts);
      return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
    };
    std::vector<double> mine, theirs;
    for (int k = 0; k <= repeats; ++k) {  // the first pair warms both (kernel compilation, Embree's first build)
      Scene s;
      s.add_instance(s.add_mesh(mesh.vertices, mesh.triangles), Mat4(1.0f));
      CommitOptions options;
      options.builder = sah ? BuilderKind::Sah : BuilderKind::Lbvh;
      options.threads = threads;
      if (idle_us) usleep(useconds_t(idle_us));
      double start = wall_ms();
      s.commit(options);
      if (k) mine.push_back(wall_ms() - start);
      if (!s.commit_stats().warning.empty()) std::fprintf(stderr, "%s\n", s.commit_stats().warning.c_str());
      if (idle_us) usleep(useconds_t(idle_us));
      start = wall_ms();
      { EmbreeScene e(mesh.vertices, mesh.triangles, false, threads, !sah); }
      if (k) theirs.push_back(wall_ms() - start);
    }
    std::sort(mine.begin(), mine.end());
    std::sort(theirs.begin(), theirs.end());
    std::printf("%s: %zu triangles, %s commit median %.4g ms, Embree %s %.4g ms wall (%d runs)\n", kind.c_str(),
                mesh.triangles.size(), sah ? "SAH" : "LBVH", mine[mine.size() / 2], sah ? "default" : "Morton",
                theirs[theirs.size() / 2], repeats);
    if (sah) return 0;
    // The stages of the kernels' build collapsed in place (build_lbvh_wide: what a commit runs on
    // an OpenCL GPU; on a CPU device the commit above builds on the host): medians of as many
    // builds as commits above.
    const PrimitiveBounds prims = triangle_bounds(mesh);
    std::vector<std::pair<std::string, std::vector<double>>> stages;
    for (int k = 0; k < repeats; ++k) {
      LbvhStats st;
      const WideBuild built = build_lbvh_wide(prims.boxes.data(), prims.boxes.size(), kBlockWidth, {}, &st);
      st.stages.emplace_back("build_lbvh_wide", st.build_ms);
      stages.resize(st.stages.size());
      for (size_t i = 0; i < st.stages.size(); ++i) {
        stages[i].first = st.stages[i].first;
        stages[i].second.push_back(st.stages[i].second);
      }
    }
    for (auto& [name, ms] : stages) {
      std::sort(ms.begin(), ms.end());
      std::printf("  %s %.1f ms\n", name.c_str(), ms[ms.size() / 2]);
    }
    return 0;
  }
  if (kind == "wide") {
    auto wall_ms = [] {
      timespec ts;
      clock_gettime(CLOCK_MONOTONIC, &ts);
      return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
    };
    const PrimitiveBounds prims = triangle_bounds(mesh);
    BinnedSahConfig sah;
    sah.leaf_without_search = kBlockWidth;  // as Mesh::build
    const Bvh trees[2] = {build_binned_sah(prims.boxes.data(), prims.boxes.size(), sah),
                          build_lbvh(prims.boxes.data(), prims.boxes.size())};
    for (int t = 0; t < 2; ++t)
      for (CollapseMethod method : {CollapseMethod::Greedy, CollapseMethod::Sah}) {
        std::vector<double> ms;
        WideBvh wide;
        for (int k = 0; k < 3; ++k) {
          const double start = wall_ms();
          wide = collapse(trees[t], kBlockWidth, method);
          ms.push_back(wall_ms() - start);
        }
        std::sort(ms.begin(), ms.end());
        const WideStats st = wide_stats(wide, kBlockWidth);
        const EmbreeMetric em = embree_metric(wide);
        std::printf(
            "wide: %zu triangles, %s tree, %s collapse: %zu nodes, %.2f children a node, SAH cost %.2f, "
            "collapse %.1f ms (median of 3); Embree's metric %.2f (nodes %.2f, leaves %.2f in blocks of 4, "
            "%.2f in blocks of 8; %.2f triangles a leaf)\n",
            mesh.triangles.size(), t ? "LBVH" : "SAH", method == CollapseMethod::Sah ? "DP" : "greedy", st.nodes,
            st.children_per_node, st.sah_cost, ms[1], em.nodes + em.blocks_of_4, em.nodes, em.blocks_of_4,
            em.blocks_of_8, em.triangles_a_leaf);
      }
    // The kernels' radix tree collapsed where it lies, as the LBVH commit does (held in host
    // memory here, so each run times the collapse alone): medians of `repeats` runs.
    const LbvhHierarchy h = build_lbvh_hierarchy_opencl(prims.boxes.data(), prims.boxes.size(), {});
    LbvhTree tree;
    tree.nodes = h.nodes.data();
    tree.root = uint32_t(h.root);
    tree.prim_bounds = prims.boxes.data();
    tree.order = h.values.data();
    tree.leaves = h.values.size();
    std::vector<double> ms;
    for (int k = 0; k < std::max(repeats, 3); ++k) {
      const double start = wall_ms();
      const WideBvh wide = collapse(tree, kBlockWidth);
      ms.push_back(wall_ms() - start);
    }
    std::sort(ms.begin(), ms.end());
    std::printf("wide: LBVH radix tree collapsed in place (DP): %.1f ms (median of %zu; fastest %.1f)\n",
                ms[ms.size() / 2], ms.size(), ms[0]);
    // The host's Morton build, straight to wide nodes, against the OpenCL build and its collapse.
    std::vector<double> host, device;
    WideBuild morton;
    for (int k = 0; k < std::max(repeats, 3); ++k) {
      double start = wall_ms();
      morton = build_morton_wide(prims.boxes.data(), prims.boxes.size(), kBlockWidth);
      host.push_back(wall_ms() - start);
      start = wall_ms();
      const WideBuild lbvh = build_lbvh_wide(prims.boxes.data(), prims.boxes.size(), kBlockWidth);
      device.push_back(wall_ms() - start);
    }
    std::sort(host.begin(), host.end());
    std::sort(device.begin(), device.end());
    const WideStats mst = wide_stats(morton.wide, kBlockWidth);
    // Blocks each tree's leaves fill (a leaf of up to 8 triangles is one block).
    auto blocks_of = [](const WideBvh& w) {
      size_t blocks = 0, triangles = 0;
      for (const WideNode& n : w.nodes)
        for (int i = 0; i < kWidth; ++i)
          if (n.count[i]) {
            blocks += (n.count[i] + kBlockWidth - 1) / kBlockWidth;
            triangles += n.count[i];
          }
      return std::pair{blocks, triangles};
    };
    const auto [host_blocks, host_triangles] = blocks_of(morton.wide);
    const auto [dp_blocks, dp_triangles] = blocks_of(collapse(tree, kBlockWidth));
    std::printf("wide: triangles a block: host Morton %.2f (%zu blocks), kernels' tree collapsed %.2f (%zu blocks)\n",
                double(host_triangles) / double(host_blocks), host_blocks, double(dp_triangles) / double(dp_blocks),
                dp_blocks);
    std::printf(
        "wide: host Morton build: %zu nodes, %.2f children a node, SAH cost %.2f, %.1f ms; OpenCL build_lbvh_wide "
        "%.1f ms (medians of %zu)\n",
        mst.nodes, mst.children_per_node, mst.sah_cost, host[host.size() / 2], device[device.size() / 2], host.size());
    return 0;
  }
  if (kind == "commit" || kind == "commit-all" || kind == "lbvh-commit") {
    // commit-all: on every core, in wall-clock milliseconds; lbvh-commit: the LBVH commit so, TOYRT
    // alone (for perf; lbvh-all times it against Embree).
    const bool lbvh = kind == "lbvh-commit";
    const bool all = kind == "commit-all" || lbvh;
    auto cpu_ms = [all] {
      timespec ts;
      clock_gettime(all ? CLOCK_MONOTONIC : CLOCK_PROCESS_CPUTIME_ID, &ts);
      return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
    };
    std::vector<double> ms;
    for (int k = 0; k <= repeats; ++k) {  // the first is a warm-up
      Scene s;
      s.add_instance(s.add_mesh(mesh.vertices, mesh.triangles), Mat4(1.0f));
      CommitOptions options;
      options.builder = lbvh ? BuilderKind::Lbvh : BuilderKind::Sah;
      options.threads = all ? 0 : 1;
      const double start = cpu_ms();
      s.commit(options);
      if (k) ms.push_back(cpu_ms() - start);
    }
    std::sort(ms.begin(), ms.end());
    std::printf("%s: %zu triangles, median %.4g ms %s (%d runs)\n", kind.c_str(), mesh.triangles.size(),
                ms[ms.size() / 2], all ? "wall" : "CPU", repeats);
    return 0;
  }
  Scene scene;
  scene.add_instance(scene.add_mesh(mesh.vertices, mesh.triangles), Mat4(1.0f));
  scene.commit();
  std::vector<Ray> primary;
  std::vector<Hit> hits;
  // TOYRT_FRAME=WxH: the camera's frame (320x240 by default). bench_trace's 1024x768 gives
  // neighbouring rays more cache lines in common, and at 1M triangles reads otherwise
  // (docs/trace-speed.md, forty-second session).
  int width = 320, height = 240;
  if (const char* frame = std::getenv("TOYRT_FRAME")) {
    if (std::sscanf(frame, "%dx%d", &width, &height) != 2 || width <= 0 || height <= 0) {
      std::fprintf(stderr, "TOYRT_FRAME=%s: expected WIDTHxHEIGHT, e.g. 1024x768\n", frame);
      return 2;
    }
  }
  for (const Ray& r : primary_rays(bounds_of(mesh), width, height)) {
    const Hit h = scene.intersect(r);
    if (!h.found()) continue;
    primary.push_back(r);
    hits.push_back(h);
  }
  const BBox box = bounds_of(mesh);
  const Vec3 light = box.center() + glm::length(box.extent()) * Vec3(-0.4f, -0.9f, 1.3f);
  // Rays leaving the surface name the triangle they leave, as bench_trace's (Ray::self).
  const std::vector<Ray> rays = kind == "primary" ? primary
                                : kind == "shadow"
                                    ? leaving_their_triangles(mesh, shadow_rays(mesh, primary, hits, light), hits)
                                    : leaving_their_triangles(mesh, diffuse_rays(mesh, primary, hits, 17), hits);
  // "embree": the same rays through Embree 3 in its default mode, for
  // instruction counts side by side (under valgrind Embree runs its AVX2 kernels).
  const bool embree = word("embree");
  const EmbreeScene peer(mesh.vertices, mesh.triangles, false, 1);
  // "room" (Embree ignores it): the same rays traced in the mesh inside a closed room of 12
  // triangles (bench_trace's closed room: with the light outside, a wall blocks every shadow ray).
  Scene in_room;
  if (room) {
    const MeshData walled = in_closed_room(mesh, 0.5f);
    in_room.add_instance(in_room.add_mesh(walled.vertices, walled.triangles), Mat4(1.0f));
    in_room.commit();
  }
  const Scene& target = room ? in_room : scene;
  const bool shadow = kind == "shadow";  // compared once: a string compare per ray would be counted too
  size_t found = 0;
  double checksum = 0.0;
  timespec t0, t1;
  // This thread's CPU time: the commit's TBB workers (and Embree's) may still spin after it.
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t0);
  for (int k = 0; k < repeats; ++k)
    for (const Ray& r : rays) {
      if (shadow) {
        found += embree ? peer.occluded(r) : target.occluded(r);
      } else {
        const Hit h = embree ? peer.intersect(r) : target.intersect(r);
        if (h.found()) {
          ++found;
          checksum += h.t;
        }
      }
    }
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t1);
  const double seconds = double(t1.tv_sec - t0.tv_sec) + 1e-9 * double(t1.tv_nsec - t0.tv_nsec);
  std::printf("%s: %zu rays x %d, %zu found, checksum %.9g, %.3f Mrays/s (CPU time)\n", kind.c_str(), rays.size(),
              repeats, found, checksum, seconds > 0.0 ? double(rays.size()) * repeats / seconds * 1e-6 : 0.0);
  return 0;
}
