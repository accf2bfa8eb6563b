// The renderer on the whole scene: closed-form pixels, the settings' bounds, "auto" light
// sampling, and the area-light estimator as a setting of the render rather than of the scene.
#include "render/renderer.h"

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include <atomic>
#include <cstdlib>
#include <new>
#include <stdexcept>

#include "render_fixtures.h"
#include "test_scenes.h"

using namespace toyrt;
using namespace toyrt::testing;

// Bytes allocated through operator new in this binary: ReadsTheSceneInPlace checks that a render
// allocates nothing the size of the scene's shading (a per-render copy of it did, tens of MB).
static std::atomic<size_t> g_new_bytes{0};
void* operator new(size_t n) {
  g_new_bytes.fetch_add(n, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, size_t) noexcept { std::free(p); }

namespace {

constexpr double kPiD = 3.14159265358979323846;

// A 20 x 20 m Lambert floor at z = 0 with albedo `albedo`.
Scene floor_scene(float albedo) { return floor_of(Lambert{Vec3(albedo), -1}); }

}  // namespace

TEST(Render, LambertFloorUnderAPointLightIsAlbedoOverPiTimesIntensityOverDistanceSquared) {
  Scene scene = floor_scene(0.5f);
  const float power = 100.0f;
  scene.add_light(PointLight::make(Vec3(0.0f, 0.0f, 1.0f), power, Vec3(1.0f)));
  scene.commit();
  const RenderResult r = render(scene, pixel_above(1e-3f), few_samples(4));
  const double expected = 0.5 / kPiD * power / (4.0 * kPiD);  // cos = 1, r = 1 m
  EXPECT_NEAR(r.rgba[0], expected, 1e-4 * expected);
  EXPECT_EQ(r.rgba[3], 1.0f);
}

TEST(Render, AnObjectWithoutShadowsLeavesTheFloorLitAsIfItWereNotThere) {
  // A point light at (1, 0, 1) and a small triangle halfway to it, out of the camera ray's way:
  // casting shadows it darkens the pixel entirely; with visible_shadow off the pixel is the
  // closed form of the open floor (cos 45 degrees, r^2 = 2).
  const float power = 100.0f;
  const double expected = 0.5 / kPiD * power / (4.0 * kPiD) * (1.0 / std::sqrt(2.0)) / 2.0;
  for (bool visible_shadow : {true, false}) {
    Scene scene = floor_scene(0.5f);
    const uint32_t blocker =
        scene.add_mesh({{0.4f, -0.1f, 0.5f}, {0.6f, -0.1f, 0.5f}, {0.5f, 0.1f, 0.5f}}, {{0, 1, 2}});
    scene.add_instance(blocker, Mat4(1.0f), visible_shadow);
    scene.add_light(PointLight::make(Vec3(1.0f, 0.0f, 1.0f), power, Vec3(1.0f)));
    scene.commit();
    const RenderResult r = render(scene, pixel_above(1e-3f), few_samples(4));
    if (visible_shadow)
      EXPECT_EQ(r.rgba[0], 0.0f);
    else
      EXPECT_NEAR(r.rgba[0], expected, 1e-4 * expected);
  }
}

TEST(Render, AutoLightSamplingSamplesEveryLightUpToFourThenOne) {
  Scene scene = floor_scene(0.5f);
  scene.commit();
  for (size_t n = 1; n <= kAllLightsUpTo + 1; ++n) {
    scene.add_light(PointLight::make(Vec3(0.0f, float(n), 1.0f), 10.0f, Vec3(1.0f)));
    const RenderResult r = render(scene, pixel_above(0.1f), few_samples(1));
    EXPECT_EQ(r.light_sampling, n <= kAllLightsUpTo ? LightSampling::All : LightSampling::One) << n << " lights";
  }
  RenderSettings all = few_samples(1);
  all.integrator.light_sampling = LightSampling::All;
  EXPECT_EQ(render(scene, pixel_above(0.1f), all).light_sampling, LightSampling::All);
}

TEST(Render, BothAreaLightEstimatorsRenderTheSameSceneToTheSameMean) {
  // The estimator is the render's: one scene, two renders, no edit in between.
  Scene scene = floor_scene(1.0f);
  scene.add_light(AreaLight::make(AreaShape::Square, 1.0f, 1.0f, glm::translate(Mat4(1.0f), Vec3(0.0f, 0.0f, 0.5f)),
                                  50.0f, Vec3(1.0f)));
  scene.commit();
  RenderSettings area = few_samples(4096), solid = few_samples(4096);
  area.integrator.area_sampling = AreaSampling::Area;
  solid.integrator.area_sampling = AreaSampling::SolidAngle;
  const float a = render(scene, pixel_above(1e-3f), area).rgba[0];
  const float s = render(scene, pixel_above(1e-3f), solid).rgba[0];
  // Under the centre of a square of side 1 at h = 0.5: E = 4 L F(0.5, 0.5, 0.5) with L = P / (4 A);
  // the pixel is E / pi for albedo 1. Howell's corner factor, a = b = 1 (side / h).
  const double x = 1.0, y = 1.0;
  const double corner = (x / std::sqrt(1 + x * x) * std::atan(y / std::sqrt(1 + x * x)) +
                         y / std::sqrt(1 + y * y) * std::atan(x / std::sqrt(1 + y * y))) /
                        (2.0 * kPiD);
  const double expected = 4.0 * kPiD * (50.0 / 4.0) * corner / kPiD;
  EXPECT_NEAR(a, expected, 0.02 * expected);
  EXPECT_NEAR(s, expected, 0.02 * expected);
}

TEST(Render, RefusesSettingsOutOfBoundsAndUncommittedScenes) {
  Scene scene = floor_scene(0.5f);
  EXPECT_THROW(render(scene, pixel_above(1.0f), few_samples(1)), std::logic_error);
  scene.commit();
  const Camera cam = pixel_above(1.0f);
  auto refused = [&](auto edit) {
    RenderSettings s = few_samples(1);
    edit(s);
    EXPECT_THROW(render(scene, cam, s), std::invalid_argument);
  };
  refused([](RenderSettings& s) { s.samples = 0; });
  refused([](RenderSettings& s) { s.first_sample = -1; });
  refused([](RenderSettings& s) { s.tile_size = 0; });
  refused([](RenderSettings& s) { s.threads = -1; });
  refused([](RenderSettings& s) { s.integrator.max_specular_depth = -1; });
  refused([](RenderSettings& s) { s.integrator.split_depth = -1; });
  EXPECT_NO_THROW(render(scene, cam, few_samples(1)));
}

TEST(RenderSettings, NamesParseAndPrintBack) {
  for (LightSampling s : {LightSampling::Auto, LightSampling::All, LightSampling::One})
    EXPECT_EQ(parse_light_sampling(light_sampling_name(s)), s);
  for (AreaSampling s : {AreaSampling::Area, AreaSampling::SolidAngle})
    EXPECT_EQ(parse_area_sampling(area_sampling_name(s)), s);
  for (BuilderKind k : {BuilderKind::Auto, BuilderKind::Sah, BuilderKind::Lbvh})
    EXPECT_EQ(parse_builder(builder_name(k)), k);
  EXPECT_THROW(parse_light_sampling("some"), std::invalid_argument);
  EXPECT_THROW(parse_area_sampling("fast"), std::invalid_argument);
  EXPECT_THROW(parse_builder("fast"), std::invalid_argument);
}

TEST(Render, ReadsTheSceneInPlace) {
  // A mesh whose shading is ~12 MB; a one-pixel render must allocate far less than that.
  const toyrt::testing::MeshData m = toyrt::testing::uv_sphere(316, 316);
  const size_t corners = 3 * m.triangles.size();
  MeshShading sh;
  sh.corner_normals.assign(corners, Vec3(0.0f, 0.0f, 1.0f));
  sh.corner_uvs.assign(corners, Vec2(0.5f));
  sh.material_ids.assign(m.triangles.size(), 0);
  const size_t shading_bytes = corners * (sizeof(Vec3) + sizeof(Vec2)) + m.triangles.size() * sizeof(int32_t);
  ASSERT_GT(shading_bytes, size_t(10) << 20);
  Scene scene;
  scene.add_instance(scene.add_mesh(m.vertices, m.triangles, std::move(sh)), Mat4(1.0f));
  scene.add_material(Lambert{});
  scene.add_light(PointLight::make(Vec3(0.0f, 0.0f, 3.0f), 10.0f, Vec3(1.0f)));
  scene.commit();
  CameraParams p;
  p.resolution_x = p.resolution_y = 1;
  p.matrix_world = glm::translate(Mat4(1.0f), Vec3(0.0f, 0.0f, 4.0f));
  const Camera cam = Camera::make(p);
  render(scene, cam, few_samples(1));  // warm-up: the thread arena's own allocations
  const size_t before = g_new_bytes.load();
  const RenderResult r = render(scene, cam, few_samples(1));
  const size_t allocated = g_new_bytes.load() - before;
  EXPECT_LT(allocated, size_t(1) << 20) << "a render allocated " << allocated << " bytes";
  EXPECT_GT(r.rgba[0], 0.0f);  // it did see the lit sphere
}
