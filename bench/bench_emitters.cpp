// Emissive triangles: the power CDF against the light tree (lights/mesh_emitters.h).
// (a) A room: a 20 x 20 m Lambert floor under a ceiling 3 m up of k x k small emissive quads (0.2 m,
// both sides emit) spread evenly over all of it, 2 k^2 triangles. Per count: the time of one
// emitter sample (choice and point) by each, the relative variance of the one-sample irradiance
// estimate L cos / pdf at floor points (no visibility: the choice's quality alone), then renders of
// the floor (32 x 32 pixels, 16 samples, one thread) by each against a 512-sample reference:
// relative RMS error and render time, and the error at equal time, sqrt(err^2 x time) of the CDF
// over the tree's (> 1: the tree is better).
// (a2) The same for one compact emitter (a ball of 2 k^2 triangles over the floor's centre), where
// the power CDF is close to the best choice and the tree's cost per pick is not repaid.
// (b) A million emissive triangles (a 708 x 708 quad height field): the build time and memory of
// the CDF and of the tree, the tree's nodes and depth, the time per sample of each, and the
// commit of a scene holding that mesh (gathering the emitters and building their tree).
// docs/lights.md, "Emissive triangles through the light tree".
//     bench_emitters [--quick] [--runs N]
#include "lights/mesh_emitters.h"
#include "render/renderer.h"
#include "sampling/rng.h"

#include "bench_util.h"
#include "light_estimates.h"
#include "render_fixtures.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

using namespace toyrt;
using namespace toyrt::testing;
using namespace toyrt::bench;

namespace {

struct Grid {
  std::vector<Vec3> vertices;
  std::vector<Triangle> triangles;
};

// k x k quads of side `quad`, centred on the cells of a `size` x `size` square at height z,
// normals down.
Grid ceiling(int k, float size, float quad, float z) {
  Grid g;
  const float cell = size / float(k);
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) {
      const Vec3 c(-0.5f * size + (float(i) + 0.5f) * cell, -0.5f * size + (float(j) + 0.5f) * cell, z);
      const uint32_t base = uint32_t(g.vertices.size());
      const float h = 0.5f * quad;
      g.vertices.insert(g.vertices.end(),
                        {c + Vec3(-h, -h, 0), c + Vec3(h, -h, 0), c + Vec3(h, h, 0), c + Vec3(-h, h, 0)});
      g.triangles.push_back({base, base + 2, base + 1});
      g.triangles.push_back({base, base + 3, base + 2});
    }
  return g;
}

// A ball of radius r centred at c: a k x 2k latitude-longitude grid (the pole rows' triangles of
// zero area are dropped by MeshEmitters::add and the scene alike).
Grid ball(int k, float r, const Vec3& c) {
  Grid g;
  for (int i = 0; i <= k; ++i)
    for (int j = 0; j <= 2 * k; ++j) {
      const float theta = kPi * float(i) / float(k), phi = kPi * float(j) / float(k);
      g.vertices.push_back(c +
                           r * Vec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)));
    }
  const auto at = [&](int i, int j) { return uint32_t(i * (2 * k + 1) + j); };
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < 2 * k; ++j) {
      g.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      g.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return g;
}

// A k x k height field over [-size/2, size/2]^2: 2 k^2 triangles of varied orientation.
Grid height_field(int k, float size) {
  Grid g;
  for (int i = 0; i <= k; ++i)
    for (int j = 0; j <= k; ++j) {
      const float x = size * (float(i) / float(k) - 0.5f), y = size * (float(j) / float(k) - 0.5f);
      g.vertices.emplace_back(x, y, 3.0f + 0.5f * std::sin(1.3f * x) * std::cos(0.7f * y));
    }
  const auto at = [&](int i, int j) { return uint32_t(i * (k + 1) + j); };
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) {
      g.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i + 1, j)});
      g.triangles.push_back({at(i, j), at(i, j + 1), at(i + 1, j + 1)});
    }
  return g;
}

MeshEmitters emitters_of(const Grid& g, const Vec3& radiance) {
  MeshEmitters e;
  for (const Triangle& t : g.triangles) {
    EmissiveTriangle et;
    et.p0 = g.vertices[t.x];
    et.e1 = g.vertices[t.y] - et.p0;
    et.e2 = g.vertices[t.z] - et.p0;
    const Vec3 n = glm::cross(et.e1, et.e2);
    et.area = 0.5f * glm::length(n);
    et.normal = n / (2.0f * et.area);
    et.radiance = radiance;
    e.add(et);
  }
  return e;
}

Scene room(const Grid& g, size_t tree_from) {
  Scene scene = floor_of(Lambert{Vec3(0.8f), -1});
  MaterialEmission glow;
  glow.radiance = Vec3(20.0f);
  const uint32_t lamp = scene.add_material(Lambert{Vec3(0.0f), -1}, glow);
  MeshShading sh;
  sh.material_ids.assign(g.triangles.size(), int32_t(lamp));
  scene.add_instance(scene.add_mesh(g.vertices, g.triangles, sh), Mat4(1.0f));
  scene.set_emitter_tree_from(tree_from, 0.0f);  // the bench compares both, whatever the spread
  scene.commit();
  return scene;
}

// Nanoseconds per sample_emitters() call at floor points, and the relative variance of L cos / pdf.
struct Sampling {
  double ns = 0.0, variance = 0.0;
};
Sampling sampling(const MeshEmitters& e, int runs) {
  constexpr uint32_t kPoints = 1024;
  std::vector<Vec3> points(kPoints);
  for (uint32_t j = 0; j < kPoints; ++j)
    points[j] = Vec3(20.0f * random_float(j, 1, 0, 2) - 10.0f, 20.0f * random_float(j, 1, 1, 2) - 10.0f, 0.0f);
  const Vec3 up(0, 0, 1);
  Sampling s;
  std::vector<double> ns;
  volatile float sink = 0.0f;
  constexpr uint32_t kCalls = 400000;
  for (int r = 0; r < runs; ++r) {
    float acc = 0.0f;
    const auto t = Clock::now();
    for (uint32_t k = 0; k < kCalls; ++k) acc += sample_emitters(e, points[k % kPoints], up, rand2(k, 3)).pdf;
    ns.push_back(ms_since(t) * 1e6 / kCalls);
    sink = sink + acc;
  }
  s.ns = median(ns);
  double total = 0.0;
  for (uint32_t j = 0; j < kPoints; j += 4) {
    const Estimate est = monte_carlo(256, [&](uint32_t k) {
      const LightSample ls = sample_emitters(e, points[j], up, rand2(k, 5 + j));
      return ls.valid() ? double(ls.radiance.x) * std::max(0.0f, glm::dot(up, ls.wi)) / double(ls.pdf) : 0.0;
    });
    if (est.mean > 0.0) total += est.standard_error * est.standard_error * 256.0 / (est.mean * est.mean);
  }
  s.variance = total / (kPoints / 4);
  return s;
}

double rms_error(const std::vector<float>& a, const std::vector<float>& ref) {
  double e = 0.0, m = 0.0;
  for (size_t i = 0; i < ref.size(); i += 4) {
    e += (double(a[i]) - ref[i]) * (double(a[i]) - ref[i]);
    m += ref[i];
  }
  const double n = double(ref.size() / 4);
  return std::sqrt(e / n) / (m / n);
}

}  // namespace

int main(int argc, char** argv) {
  const auto args = bench::parse_args(argc, argv, "bench_emitters [--quick] [--runs N]", 3);
  if (!args) return 2;
  const std::vector<int> sides =
      args->quick ? std::vector<int>{2, 6, 16, 64} : std::vector<int>{2, 3, 4, 5, 6, 8, 11, 16, 23, 32, 64, 128};
  std::printf("# %s\n", bench::cpu_model().c_str());
  CameraParams cp;
  cp.type = CameraType::Orthographic;
  cp.ortho_scale = 20.0f;
  cp.resolution_x = cp.resolution_y = 32;
  cp.matrix_world = glm::translate(Mat4(1.0f), Vec3(0.0f, 0.0f, 2.5f));  // below the ceiling: it sees the floor
  const Camera camera = Camera::make(cp);
  for (const bool compact : {false, true}) {
    std::printf(compact ? "# (a2) one emissive ball, 0.5 m radius, 1.5 m over the floor's centre\n"
                        : "# (a) room: ceiling of k x k emissive quads (0.2 m) over a 20 x 20 m floor\n");
    std::printf("%9s %8s %8s %9s %9s %9s %9s %9s %9s %10s\n", "triangles", "cdf_ns", "tree_ns", "cdf_var", "tree_var",
                "cdf_err", "tree_err", "cdf_ms", "tree_ms", "err_ratio");
    for (const int k : sides) {
      const Grid g = compact ? ball(k, 0.5f, Vec3(0.0f, 0.0f, 1.5f)) : ceiling(k, 20.0f, 0.2f, 3.0f);
      MeshEmitters cdf = emitters_of(g, Vec3(20.0f)), tree = cdf;
      cdf.finish(SIZE_MAX);
      tree.finish(1);
      const Sampling sc = sampling(cdf, args->runs), st = sampling(tree, args->runs);
      Scene by_cdf = room(g, SIZE_MAX), by_tree = room(g, 1);
      RenderSettings ref_settings = few_samples(args->quick ? 128 : 512);
      ref_settings.integrator.seed = 99;
      const std::vector<float> ref = render(by_tree, camera, ref_settings).rgba;
      const RenderSettings settings = few_samples(16);
      std::vector<double> cdf_ms, tree_ms;
      double cdf_err = 0.0, tree_err = 0.0;
      for (int r = 0; r < args->runs; ++r) {
        const RenderResult a = render(by_cdf, camera, settings), b = render(by_tree, camera, settings);
        cdf_ms.push_back(a.render_ms);
        tree_ms.push_back(b.render_ms);
        cdf_err = rms_error(a.rgba, ref);
        tree_err = rms_error(b.rgba, ref);
      }
      const double ratio = std::sqrt(cdf_err * cdf_err * median(cdf_ms) / (tree_err * tree_err * median(tree_ms)));
      std::printf("%9zu %8.1f %8.1f %9.3f %9.3f %9.4f %9.4f %9.1f %9.1f %10.2f\n", cdf.triangles.size(), sc.ns, st.ns,
                  sc.variance, st.variance, cdf_err, tree_err, median(cdf_ms), median(tree_ms), ratio);
      std::fflush(stdout);
    }
  }

  std::printf("# leaf size: the room of 8192 triangles, the ball of 992 (sampling alone)\n");
  for (const uint32_t leaf : {1u, 2u, 4u, 8u}) {
    for (const bool compact : {false, true}) {
      const Grid g = compact ? ball(16, 0.5f, Vec3(0.0f, 0.0f, 1.5f)) : ceiling(64, 20.0f, 0.2f, 3.0f);
      MeshEmitters e = emitters_of(g, Vec3(20.0f));
      e.finish(1, leaf);
      const Sampling s = sampling(e, args->runs);
      std::printf("leaf %u %s: %.1f ns/sample, variance %.3f, %zu nodes\n", leaf, compact ? "ball" : "room", s.ns,
                  s.variance, e.tree.node_count());
    }
  }

  std::printf("# (b) a million emissive triangles (a 708 x 708 quad height field)\n");
  const Grid big = height_field(args->quick ? 200 : 708, 20.0f);
  MeshEmitters base = emitters_of(big, Vec3(5.0f));
  std::vector<double> cdf_build, tree_build;
  MeshEmitters cdf = base, tree = base;
  for (int r = 0; r < args->runs; ++r) {
    cdf = base;
    tree = base;
    auto t = Clock::now();
    cdf.finish(SIZE_MAX);
    cdf_build.push_back(ms_since(t));
    t = Clock::now();
    tree.finish(1);
    tree_build.push_back(ms_since(t));
  }
  const Sampling sc = sampling(cdf, 1), st = sampling(tree, 1);
  std::printf("triangles %zu\n", base.triangles.size());
  std::printf("cdf:  build %.1f ms, %.1f MB (triangles and keys %.1f MB), %.1f ns/sample, variance %.3f\n",
              median(cdf_build), cdf.memory_bytes() / 1048576.0,
              (cdf.memory_bytes() - cdf.cdf.capacity() * sizeof(float)) / 1048576.0, sc.ns, sc.variance);
  std::printf("tree: build %.1f ms, %.1f MB (the tree %.1f MB: %zu nodes, depth %d), %.1f ns/sample, variance %.3f\n",
              median(tree_build), tree.memory_bytes() / 1048576.0, tree.tree.memory_bytes() / 1048576.0,
              tree.tree.node_count(), tree.tree.depth(), st.ns, st.variance);
  {
    Scene scene = room(big, kEmitterTreeFrom);
    const CommitStats& s = scene.commit_stats();
    std::printf("scene commit: %.1f ms, of which emitters (gather + tree) %.1f ms; %zu emissive triangles, %zu nodes\n",
                s.build_ms, s.emitters_ms, s.emissive_triangles, s.emitter_tree_nodes);
  }
  return 0;
}
