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
using namespace toyrt::bench;

namespace {

template <class Tracer>
double mrays(const std::vector<Ray>& rays, int runs, const Tracer& tracer) {
  const double ms = best_ms(runs, [&] { for_each_ray(rays, tracer); });
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
  const std::optional<Args> args = parse_args(argc, argv, "--csv FILE.csv [--dump DIR] [--runs N] [--quick]", 2);
  if (!args) return 2;
  const int width = args->quick ? 192 : 384, height = args->quick ? 144 : 288;

  {  // Compile the LBVH kernels once, outside every timing.
    const CommitStats warm = compile_lbvh_kernels();
    if (!warm.warning.empty()) std::fprintf(stderr, "%s\n", warm.warning.c_str());
  }

  std::ofstream csv(args->csv);
  csv << "triangles,builder,build_ms,sah_cost,primary_mrays,diffuse_mrays,shadow_mrays,rays_primary,rays_diffuse,"
         "rays_shadow,auto_preview,auto_final,device\n";
  const BuilderCostModel model;
  // Workloads as bench_lbvh counts them: one primary, one shadow and one bounce ray per sample.
  const double preview_rays = 640.0 * 360 * 3, final_rays = 1920.0 * 1080 * 64 * 3;
  for (int r : sphere_rings(args->quick)) {
    const MeshData m = uv_sphere(r, r, 1.0f, 0.15f);
    const size_t n = m.triangles.size();
    std::fprintf(stderr, "bench_accel: %zu triangles\n", n);
    const EmbreeScene embree(m.vertices, m.triangles);
    const RaySets sets = ray_sets(m, embree, width, height);
    const std::vector<Ray>&primary = sets.primary, &diffuse = sets.diffuse, &shadow = sets.shadow;
    if (!args->dump.empty()) {
      const std::string base = args->dump + "/accel-" + std::to_string(n);
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
      std::snprintf(line, sizeof line, "%zu,%s,%.3f,%.3f,%.4f,%.4f,%.4f,%zu,%zu,%zu,%s,%s,%s\n", n, name, build, cost,
                    p, d, s, primary.size(), diffuse.size(), shadow.size(), pick_preview, pick_final,
                    opencl::device().name.c_str());
      csv << line;
      std::fprintf(stderr, "%s", line);
    };
    for (BuilderKind kind : {BuilderKind::Sah, BuilderKind::Lbvh}) {
      Bvh tree;
      const double build = kind == BuilderKind::Sah
                               ? best_ms(args->runs, [&] { tree = build_binned_sah(prims.boxes.data(), n); })
                               : best_ms(args->runs, [&] { tree = build_lbvh(prims.boxes.data(), n, {}); });
      const auto s = scene_of(m, kind);
      auto hit = [&](const Ray& ray) { s->intersect(ray); };
      auto occ = [&](const Ray& ray) { s->occluded(ray); };
      row(kind == BuilderKind::Sah ? "sah" : "lbvh", build, tree.sah_cost(), mrays(primary, args->runs, hit),
          mrays(diffuse, args->runs, hit), mrays(shadow, args->runs, occ));
    }
    const double build = best_ms(args->runs, [&] { EmbreeScene e(m.vertices, m.triangles); });
    auto hit = [&](const Ray& ray) { embree.intersect(ray); };
    auto occ = [&](const Ray& ray) { embree.occluded(ray); };
    row("embree", build, 0.0, mrays(primary, args->runs, hit), mrays(diffuse, args->runs, hit),
        mrays(shadow, args->runs, occ));
  }
  return 0;
}
