// Trace benchmark: the same meshes and rays through TOYRT and Embree 3 in one process, on one
// thread and on all, reported as ratios to Embree (timings on shared machines are noisy; ratios
// measured side by side, best of several runs, are what carry over). Writes a Markdown table.
//
//   bench_trace [--out FILE] [--runs N] [--quick]
#include "bench_util.h"
#include "core/parallel.h"
#include "embree_oracle.h"
#include "oracle_compare.h"
#include "scene/scene.h"
#include "test_scenes.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

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

struct Flat {  // a ray set as the batch API takes it
  std::vector<float> org, dir, tfar;
  size_t count = 0;
};

Flat flatten(const std::vector<Ray>& rays) {
  Flat f;
  f.count = rays.size();
  for (const Ray& r : rays) {
    f.org.insert(f.org.end(), {r.org.x, r.org.y, r.org.z});
    f.dir.insert(f.dir.end(), {r.dir.x, r.dir.y, r.dir.z});
    f.tfar.push_back(r.tfar);
  }
  return f;
}

struct Row {
  std::string mesh, rays, threads;
  size_t count;
  double toyrt_ms, embree_ms;
};

}  // namespace

int main(int argc, char** argv) {
  const std::optional<Args> args = parse_args(argc, argv, "[--out FILE] [--runs N] [--quick]", 5);
  if (!args) return 2;
  const std::string& out_path = args->out;
  const int runs = args->runs;
  const bool quick = args->quick;
  const int all = int(std::thread::hardware_concurrency());
  const int width = quick ? 320 : 1024, height = quick ? 240 : 768;

  struct Case {
    std::string name;
    MeshData mesh;
  };
  std::vector<Case> cases;
  cases.push_back({"bumpy sphere, 1.0M triangles", uv_sphere(708, 708, 1.0f, 0.15f)});
  cases.push_back({"triangle soup, 200K triangles", triangle_soup(200000, 0.02f, 1)});

  std::ostringstream md, builds;
  std::vector<Row> rows;
  builds << "| mesh | threads | TOYRT build ms | Embree build ms | TOYRT / Embree (time) |\n|---|---|---|---|---|\n";
  for (const Case& c : cases) {
    std::fprintf(stderr, "%s\n", c.name.c_str());
    // Builds, each thread count.
    for (int threads : {1, all}) {
      const double mine = best_ms(std::max(1, runs / 2), [&] {
        Scene s;
        s.add_instance(s.add_mesh(c.mesh.vertices, c.mesh.triangles), Mat4(1.0f));
        CommitOptions opt;
        opt.builder = BuilderKind::Sah;
        opt.threads = threads;
        s.commit(opt);
      });
      const double theirs =
          best_ms(std::max(1, runs / 2), [&] { EmbreeScene e(c.mesh.vertices, c.mesh.triangles, false, threads); });
      char line[256];
      std::snprintf(line, sizeof line, "| %s | %d | %.0f | %.0f | %.2f |\n", c.name.c_str(), threads, mine, theirs,
                    mine / theirs);
      builds << line;
    }
    Scene scene;
    scene.add_instance(scene.add_mesh(c.mesh.vertices, c.mesh.triangles), Mat4(1.0f));
    scene.commit();
    const EmbreeScene embree(c.mesh.vertices, c.mesh.triangles);

    const std::vector<Ray> primary = primary_rays(bounds_of(c.mesh), width, height);
    std::vector<Hit> hits(primary.size());
    for (size_t i = 0; i < primary.size(); ++i) hits[i] = embree.intersect(primary[i]);
    const BBox box = bounds_of(c.mesh);
    const Vec3 light = box.center() + glm::length(box.extent()) * Vec3(-0.4f, -0.9f, 1.3f);
    const std::vector<std::pair<std::string, std::vector<Ray>>> sets = {
        {"primary", primary},
        {"diffuse", diffuse_rays(c.mesh, primary, hits, 17)},
        {"shadow", shadow_rays(c.mesh, primary, hits, light)}};

    for (const auto& [kind, rays] : sets) {
      const Flat f = flatten(rays);
      const bool shadow = kind == "shadow";
      const float tnear = 0.0f;
      const RayBatch batch{f.org.data(), f.dir.data(), &tnear, 0, f.tfar.data(), 1, f.count};
      std::vector<float> t(f.count), u(f.count), v(f.count);
      std::vector<int32_t> prim(f.count), inst(f.count);
      std::vector<uint8_t> blocked(f.count);
      for (int threads : {1, all}) {
        const double mine = best_ms(runs, [&] {
          if (shadow)
            scene.occluded(batch, blocked.data(), threads);
          else
            scene.intersect(batch, {t.data(), u.data(), v.data(), prim.data(), inst.data()}, threads);
        });
        // Embree through the same harness: TBB tasks of 256 rays, single-ray queries.
        const double theirs = best_ms(runs, [&] {
          run_with_threads(threads, [&] {
            tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 256),
                              [&](const tbb::blocked_range<size_t>& r) {
                                for (size_t i = r.begin(); i != r.end(); ++i) {
                                  if (shadow)
                                    blocked[i] = embree.occluded(rays[i]);
                                  else
                                    t[i] = embree.intersect(rays[i]).t;
                                }
                              });
          });
        });
        rows.push_back({c.name, kind, std::to_string(threads), rays.size(), mine, theirs});
        std::fprintf(stderr, "  %-8s %d thread(s): TOYRT %.1f Mrays/s, Embree %.1f Mrays/s\n", kind.c_str(), threads,
                     rays.size() / mine / 1e3, rays.size() / theirs / 1e3);
      }
    }
  }

  char date[64];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  md << "# Trace benchmark: TOYRT against Embree " << RTC_VERSION_STRING << "\n\n"
     << "Written by `make bench-trace` (`build/bench/bench_trace`) on " << date << ": " << cpu_model() << ", " << all
     << " hardware threads. Best of " << runs << " runs for tracing, each engine in the same process on the "
     << "same rays; Embree 3 with its default scene flags and build quality, single-ray queries "
     << "(`rtcIntersect1`/`rtcOccluded1`) through the same TBB harness as TOYRT's batch API. Rays: a " << width << "x"
     << height << " pinhole camera (primary), one cosine-distributed bounce from each primary hit "
     << "(diffuse), and one ray from each primary hit to a point light (shadow, any-hit query).\n\n"
     << "## Tracing\n\n| mesh | rays | threads | count | TOYRT Mrays/s | Embree Mrays/s | TOYRT / Embree |\n"
     << "|---|---|---|---|---|---|---|\n";
  for (const Row& r : rows) {
    char line[512];
    std::snprintf(line, sizeof line, "| %s | %s | %s | %zu | %.2f | %.2f | **%.2f** |\n", r.mesh.c_str(),
                  r.rays.c_str(), r.threads.c_str(), r.count, r.count / r.toyrt_ms / 1e3, r.count / r.embree_ms / 1e3,
                  r.embree_ms / r.toyrt_ms);
    md << line;
  }
  md << "\n## Building\n\n" << builds.str();

  // Watertightness: rays from inside closed meshes aimed exactly at every vertex, every edge
  // midpoint and four random points on every edge (tests/native/watertight_test.cpp asserts
  // TOYRT's zero; this records everyone's counts).
  md << "\n## Watertightness\n\nRays from inside a closed mesh aimed exactly at its vertices and edges; "
     << "every one should hit.\n\n| mesh | rays | TOYRT misses | Embree default misses | Embree robust misses |\n"
     << "|---|---|---|---|---|\n";
  struct Closed {
    std::string name;
    MeshData mesh;
    Vec3 inside;
  };
  const Vec3 far_offset(1e5f, -5e4f, 2.5e4f);
  const std::vector<Closed> closed = {
      {"UV sphere, 39,600 triangles", uv_sphere(100, 200), Vec3(0.0f)},
      {"fan: 2 vertices shared by 5,000 triangles each", bicone_fan(5000), Vec3(0.01f, 0.02f, 0.0f)},
      {"bumpy sphere, 89,400 triangles", uv_sphere(150, 300, 1.0f, 0.2f), Vec3(0.05f)},
      {"sphere 1e5 from the origin", transformed(uv_sphere(60, 120), 1.0f, far_offset), far_offset},
      {"sphere at scale 1e-3", transformed(uv_sphere(60, 120), 1e-3f, Vec3(0.0f)), Vec3(0.0f)},
  };
  for (const Closed& c : closed) {
    Scene scene;
    scene.add_instance(scene.add_mesh(c.mesh.vertices, c.mesh.triangles), Mat4(1.0f));
    scene.commit();
    const EmbreeScene fast(c.mesh.vertices, c.mesh.triangles, false), robust(c.mesh.vertices, c.mesh.triangles, true);
    size_t mine = 0, fast_misses = 0, robust_misses = 0;
    const std::vector<Ray> rays = rays_at_vertices_and_edges(c.mesh, c.inside, 4, 99);
    for (const Ray& r : rays) {
      mine += !scene.intersect(r).found();
      fast_misses += !fast.intersect(r).found();
      robust_misses += !robust.intersect(r).found();
    }
    char line[512];
    std::snprintf(line, sizeof line, "| %s | %zu | **%zu** | %zu (%.2f %%) | %zu (%.3f %%) |\n", c.name.c_str(),
                  rays.size(), mine, fast_misses, 100.0 * fast_misses / rays.size(), robust_misses,
                  100.0 * robust_misses / rays.size());
    md << line;
  }
  // Accuracy against a double-precision evaluation on the same float geometry and rays
  // (tests/support/oracle_compare.h classifies every disagreement).
  md << "\n## Accuracy\n\nPrimary rays (" << width << "x" << height
     << ") against the double-precision answer on the same float "
     << "geometry: the largest error of t relative to the hit distance (or to 1 % of the coordinates' magnitude where "
        "that is larger, since float positions carry that much absolute error), hits Embree missed although the ray "
        "crosses a nearer triangle "
     << "(leaks), and hits reported where the ray crosses nothing (false hits). TOYRT's own misses and false hits are "
     << "asserted to be zero by `tests/native/embree_oracle_test.cpp`.\n\n"
     << "| mesh | TOYRT max t error | Embree max t error | Embree leaks | Embree false hits | TOYRT errors |\n"
     << "|---|---|---|---|---|---|\n";
  const std::vector<Case> accuracy = {
      {"10^4:1 slivers, 50K", slivers(50000, 2)},
      {"bumpy sphere 1e5 from the origin", transformed(uv_sphere(100, 200, 1.0f, 0.2f), 1.0f, Vec3(1e5f, -1e5f, 5e4f))},
      {"bumpy sphere at scale 1e-3", transformed(uv_sphere(100, 200, 1.0f, 0.2f), 1e-3f, Vec3(0.0f))},
  };
  for (const Case& c : accuracy) {
    Scene scene;
    scene.add_instance(scene.add_mesh(c.mesh.vertices, c.mesh.triangles), Mat4(1.0f));
    scene.commit();
    const EmbreeScene embree(c.mesh.vertices, c.mesh.triangles);
    const Agreement a = compare_with_embree(scene, embree, c.mesh, primary_rays(bounds_of(c.mesh), width, height));
    char line[512];
    std::snprintf(line, sizeof line, "| %s | %.1e | %.1e | %zu | %zu | %zu |\n", c.name.c_str(), a.max_t_rel_error,
                  a.max_t_rel_error_embree, a.embree_leaks, a.embree_false_hits,
                  a.toyrt_misses + a.toyrt_false_hits + a.t_mismatches + a.uv_mismatches);
    md << line;
  }
  std::cout << md.str();
  if (!out_path.empty()) {
    std::ofstream out(out_path);
    out << md.str();
    std::fprintf(stderr, "wrote %s\n", out_path.c_str());
  }
  return 0;
}
