// Acceleration structures for docs/results.md, section 2: build time and trace speed for primary,
// diffuse and shadow rays, 10K to 4M triangles, for the binned SAH builder, LBVH (OpenCL kernels
// on PoCL) and Embree 3; the totals (build + trace) of a preview and a final render, and what
// `auto` picks for them. Writes a CSV; with --dump DIR also each mesh and its three ray sets as
// raw float32/uint32 files, so that bench/accel_python.py can give Open3D the very same rays.
//
//   bench_accel --csv FILE.csv [--dump DIR] [--runs N] [--quick]
#include "accel/binned_sah_builder.h"
#include "accel/builder.h"
#include "accel/lbvh_builder.h"
#include "bench_util.h"
#include "embree_oracle.h"
#include "opencl/device.h"
#include "scene/scene.h"
#include "test_scenes.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

using namespace toyrt;
using namespace toyrt::testing;
using toyrt::bench::best_ms;

namespace {

template <class Tracer>
double mrays(const std::vector<Ray>& rays, int runs, const Tracer& tracer) {
  const double ms = best_ms(runs, [&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i) tracer(rays[i]);
    });
  });
  return rays.size() / ms / 1e3;
}

void dump(const std::string& path, const void* data, size_t bytes) {
  std::ofstream(path, std::ios::binary).write(static_cast<const char*>(data), std::streamsize(bytes));
}

void dump_rays(const std::string& path, const std::vector<Ray>& rays) {
  // Per ray: origin xyz, direction xyz, tnear, tfar (float32).
  std::vector<float> v;
  v.reserve(rays.size() * 8);
  for (const Ray& r : rays) v.insert(v.end(), {r.org.x, r.org.y, r.org.z, r.dir.x, r.dir.y, r.dir.z, r.tnear, r.tfar});
  dump(path, v.data(), v.size() * sizeof(float));
}

}  // namespace

int main(int argc, char** argv) {
  std::string csv_path, dump_dir;
  int runs = 2;
  bool quick = false;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--csv") && i + 1 < argc) csv_path = argv[++i];
    else if (!std::strcmp(argv[i], "--dump") && i + 1 < argc) dump_dir = argv[++i];
    else if (!std::strcmp(argv[i], "--runs") && i + 1 < argc) runs = std::max(1, std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--quick")) quick = true;
    else {
      std::fprintf(stderr, "usage: %s --csv FILE.csv [--dump DIR] [--runs N] [--quick]\n", argv[0]);
      return 2;
    }
  }
  // 2 r^2 triangles: 10K, 100K, 1M, 4M.
  const std::vector<int> rings = quick ? std::vector<int>{71, 224} : std::vector<int>{71, 224, 708, 1415};
  const int width = quick ? 192 : 384, height = quick ? 144 : 288;

  {  // Compile the LBVH kernels once, outside every timing.
    const MeshData warm = uv_sphere(10, 10);
    Scene s;
    s.add_instance(s.add_mesh(warm.vertices, warm.triangles), Mat4(1.0f));
    CommitOptions o;
    o.builder = BuilderKind::Lbvh;
    s.commit(o);
    if (!s.commit_stats().warning.empty()) std::fprintf(stderr, "%s\n", s.commit_stats().warning.c_str());
  }

  std::ofstream csv(csv_path);
  csv << "triangles,builder,build_ms,sah_cost,primary_mrays,diffuse_mrays,shadow_mrays,rays_primary,rays_diffuse,"
         "rays_shadow,auto_preview,auto_final,device\n";
  const BuilderCostModel model;
  // Workloads as bench_lbvh counts them: one primary, one shadow and one bounce ray per sample.
  const double preview_rays = 640.0 * 360 * 3, final_rays = 1920.0 * 1080 * 64 * 3;
  for (int r : rings) {
    const MeshData m = uv_sphere(r, r, 1.0f, 0.15f);
    const size_t n = m.triangles.size();
    std::fprintf(stderr, "bench_accel: %zu triangles\n", n);
    const EmbreeScene embree(m.vertices, m.triangles);
    const std::vector<Ray> primary = primary_rays(bounds_of(m), width, height);
    std::vector<Hit> hits;
    for (const Ray& ray : primary) hits.push_back(embree.intersect(ray));
    const BBox box = bounds_of(m);
    const Vec3 light = box.center() + glm::length(box.extent()) * Vec3(-0.4f, -0.9f, 1.3f);
    const std::vector<Ray> diffuse = diffuse_rays(m, primary, hits, 3), shadow = shadow_rays(m, primary, hits, light);
    if (!dump_dir.empty()) {
      const std::string base = dump_dir + "/accel-" + std::to_string(n);
      dump(base + ".verts.bin", m.vertices.data(), m.vertices.size() * sizeof(Vec3));
      dump(base + ".tris.bin", m.triangles.data(), m.triangles.size() * sizeof(Triangle));
      dump_rays(base + ".primary.bin", primary);
      dump_rays(base + ".diffuse.bin", diffuse);
      dump_rays(base + ".shadow.bin", shadow);
    }
    const PrimitiveBounds prims = triangle_bounds(m);
    const char* pick_preview = model.choose(n, preview_rays) == BuilderKind::Lbvh ? "lbvh" : "sah";
    const char* pick_final = model.choose(n, final_rays) == BuilderKind::Lbvh ? "lbvh" : "sah";
    auto row = [&](const char* name, double build, double cost, double p, double d, double s) {
      char line[512];
      std::snprintf(line, sizeof line, "%zu,%s,%.3f,%.3f,%.4f,%.4f,%.4f,%zu,%zu,%zu,%s,%s,%s\n", n, name, build, cost, p, d,
                    s, primary.size(), diffuse.size(), shadow.size(), pick_preview, pick_final,
                    opencl::device().name.c_str());
      csv << line;
      std::fprintf(stderr, "%s", line);
    };
    for (BuilderKind kind : {BuilderKind::Sah, BuilderKind::Lbvh}) {
      Bvh tree;
      const double build = kind == BuilderKind::Sah
          ? best_ms(runs, [&] { tree = build_binned_sah(prims.boxes.data(), prims.centers.data(), n); })
          : best_ms(runs, [&] { tree = build_lbvh(prims.boxes.data(), prims.centers.data(), n, {}); });
      Scene s;
      s.add_instance(s.add_mesh(m.vertices, m.triangles), Mat4(1.0f));
      CommitOptions o;
      o.builder = kind;
      s.commit(o);
      auto hit = [&](const Ray& ray) { s.intersect(ray); };
      auto occ = [&](const Ray& ray) { s.occluded(ray); };
      row(kind == BuilderKind::Sah ? "sah" : "lbvh", build, tree.sah_cost(), mrays(primary, runs, hit),
          mrays(diffuse, runs, hit), mrays(shadow, runs, occ));
    }
    const double build = best_ms(runs, [&] { EmbreeScene e(m.vertices, m.triangles); });
    auto hit = [&](const Ray& ray) { embree.intersect(ray); };
    auto occ = [&](const Ray& ray) { embree.occluded(ray); };
    row("embree", build, 0.0, mrays(primary, runs, hit), mrays(diffuse, runs, hit), mrays(shadow, runs, occ));
  }
  return 0;
}
