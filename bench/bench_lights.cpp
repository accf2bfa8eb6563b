// Light selection with many lights: the linear selector against the light tree
// (lights/light_tree.h), for N point lights placed at random over a 40 x 40 m plane 0.5 to 3 m up
// and receivers at random on the floor below, facing up. Per N: the time per selection of each
// (medians of interleaved repeats), the variance of the one-sample irradiance estimate relative
// to the exact sum (so the error at equal time is sqrt(variance x time)), the tree's build time
// and memory; then the wall time of a 64 x 64 render of a Lambert floor under the same lights,
// one light per hit, through each (the linear one by a light added after the commit, which the
// scene then selects linearly until the next commit). The lights are round (radius 0.1 to 0.5 m,
// soft falloff): delta lights make the linear selector, whose weights are each light's exact
// contribution on an open floor, a zero-variance estimator, which no real scene is. Then the same
// for spots at the same places, aimed down within 45 degrees, with 60 degree cones.
// docs/lights.md, "Light selection".
//     bench_lights [--quick] [--runs N]
#include "lights/light_selector.h"
#include "lights/light_tree.h"
#include "render/renderer.h"
#include "sampling/rng.h"

#include "bench_util.h"
#include "light_estimates.h"
#include "render_fixtures.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

using namespace toyrt;
using namespace toyrt::testing;
using namespace toyrt::bench;

namespace {

std::vector<Light> plane_lights(size_t count) {
  std::vector<Light> lights;
  for (uint32_t i = 0; i < count; ++i)
    lights.emplace_back(
        PointLight::make(Vec3(40.0f * random_float(i, 0, 0, 1) - 20.0f, 40.0f * random_float(i, 0, 1, 1) - 20.0f,
                              0.5f + 2.5f * random_float(i, 0, 2, 1)),
                         1.0f + 99.0f * random_float(i, 0, 3, 1), Vec3(1.0f), 0.1f + 0.4f * random_float(i, 0, 4, 1)));
  return lights;
}

// The same positions, radii and powers as spots aimed down, tilted up to 45 degrees, with a 60
// degree cone: their bounds carry the cone, so clusters aimed away from a receiver weigh zero.
std::vector<Light> plane_spots(size_t count) {
  std::vector<Light> lights;
  for (uint32_t i = 0; i < count; ++i) {
    SpotLight::Settings s;
    const Vec3 at(40.0f * random_float(i, 0, 0, 1) - 20.0f, 40.0f * random_float(i, 0, 1, 1) - 20.0f,
                  0.5f + 2.5f * random_float(i, 0, 2, 1));
    const float azimuth = 2.0f * kPi * random_float(i, 0, 5, 1);
    s.matrix = glm::rotate(glm::translate(Mat4(1.0f), at), 0.25f * kPi * random_float(i, 0, 6, 1),
                           Vec3(std::cos(azimuth), std::sin(azimuth), 0.0f));
    s.power = 1.0f + 99.0f * random_float(i, 0, 3, 1);
    s.radius = 0.1f + 0.4f * random_float(i, 0, 4, 1);
    s.spot_size = kPi / 3.0f;
    lights.emplace_back(SpotLight::make(s));
  }
  return lights;
}

}  // namespace

int main(int argc, char** argv) {
  const auto args = bench::parse_args(argc, argv, "bench_lights [--quick] [--runs N]", 5);
  if (!args) return 2;
  const std::vector<size_t> counts = args->quick
                                         ? std::vector<size_t>{4, 16, 100, 1000}
                                         : std::vector<size_t>{2, 4, 8, 16, 32, 64, 100, 300, 1000, 3000, 10000};
  std::printf("# %s\n", bench::cpu_model().c_str());
  std::printf("%6s %6s %10s %10s %9s %9s %10s %10s %9s %9s %9s %10s %10s %10s\n", "kind", "lights", "linear_ns",
              "tree_ns", "lin_var", "tree_var", "err_render", "build_ms", "tree_KB", "nodes", "depth", "err_select",
              "render_lin", "render_tree");
  constexpr uint32_t kReceivers = 2048;
  for (const bool spots : {false, true})
    for (const size_t n : counts) {
      const std::vector<Light> lights = spots ? plane_spots(n) : plane_lights(n);
      std::vector<double> build;
      for (int r = 0; r < args->runs; ++r) {
        const auto t = Clock::now();
        const LightTree tree(lights);
        build.push_back(ms_since(t));
      }
      const LightTree tree(lights);
      const LightSelector linear(lights), through_tree(lights, &tree);
      std::vector<Vec3> points(kReceivers);
      for (uint32_t j = 0; j < kReceivers; ++j)
        points[j] = Vec3(40.0f * random_float(j, 1, 0, 2) - 20.0f, 40.0f * random_float(j, 1, 1, 2) - 20.0f, 0.0f);
      const Vec3 up(0, 0, 1);
      // Time: selections only, interleaved repeats; the sink keeps the work alive.
      const uint32_t picks = uint32_t(std::max<size_t>(1, 2000000 / (n + 50)));
      std::vector<double> lin_ns, tree_ns;
      volatile float sink = 0.0f;
      for (int r = 0; r < args->runs; ++r) {
        for (const LightSelector* s : {&linear, &through_tree}) {
          float acc = 0.0f;
          const auto t = Clock::now();
          for (uint32_t k = 0; k < picks; ++k)
            acc += s->select(points[k % kReceivers], up, random_float(k, 2, 0, 3)).probability;
          (s == &linear ? lin_ns : tree_ns).push_back(ms_since(t) * 1e6 / picks);
          sink = sink + acc;
        }
      }
      // Variance of the estimate over its mean squared, averaged over receivers: 256 one-sample
      // estimates each (both are unbiased: their means agree).
      const auto relative_variance = [&](const LightSelector& s) {
        double total = 0.0;
        for (uint32_t j = 0; j < kReceivers; j += 4) {
          const Estimate e = monte_carlo(256, [&](uint32_t k) {
            const LightSelection pick = s.select(points[j], up, random_float(k, j, 0, 4));
            if (!pick.found()) return 0.0;
            return irradiance_sample(lights[size_t(pick.index)], points[j], up, rand2(k, 5 + j)) / pick.probability;
          });
          if (e.mean > 0.0) total += e.standard_error * e.standard_error * 256.0 / (e.mean * e.mean);
        }
        return total / (kReceivers / 4);
      };
      const double lin_var = relative_variance(linear), tree_var = relative_variance(through_tree);
      const double lin_t = median(lin_ns), tree_t = median(tree_ns);
      // The render: a Lambert floor, 64 x 64 pixels over 40 m, 8 samples, one light per hit.
      Scene scene = floor_of(Lambert{Vec3(0.8f), -1});
      for (const Light& l : lights) scene.add_light(l);
      scene.commit();
      CameraParams cp;
      cp.type = CameraType::Orthographic;
      cp.ortho_scale = 40.0f;
      cp.resolution_x = cp.resolution_y = args->quick ? 32 : 64;
      cp.matrix_world = glm::translate(Mat4(1.0f), Vec3(0.0f, 0.0f, 5.0f));
      const Camera camera = Camera::make(cp);
      RenderSettings settings = few_samples(8);
      settings.integrator.light_sampling = LightSampling::One;
      std::vector<double> render_lin, render_tree;
      for (int r = 0; r < args->runs; ++r) {
        render_tree.push_back(render(scene, camera, settings).render_ms);
        scene.add_light(PointLight::make(Vec3(0.0f, 0.0f, 1.0f), 0.0f, Vec3(1.0f)));  // now stale: linear
        render_lin.push_back(render(scene, camera, settings).render_ms);
        scene.clear_lights();
        for (const Light& l : lights) scene.add_light(l);
        scene.commit();
      }
      // Error at equal time: sqrt(variance x time per sample), the render's time per sample.
      const double err_ratio = std::sqrt(lin_var * median(render_lin) / (tree_var * median(render_tree)));
      const double select_err_ratio = std::sqrt(lin_var * lin_t / (tree_var * tree_t));
      std::printf("%6s %6zu %10.1f %10.1f %9.4f %9.4f %10.2f %10.3f %9.1f %9zu %9d %10.2f %10.1f %10.1f\n",
                  spots ? "spots" : "points", n, lin_t, tree_t, lin_var, tree_var, err_ratio, median(build),
                  tree.memory_bytes() / 1024.0, tree.node_count(), tree.depth(), select_err_ratio, median(render_lin),
                  median(render_tree));
      std::fflush(stdout);
    }
  return 0;
}
