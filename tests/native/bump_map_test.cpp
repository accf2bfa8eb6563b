// The Bump node's normal (materials/normal_map.h, render/normal_mapping.cpp): a height that rises
// linearly tilts the normal by its slope times Distance, whatever tangent vectors measure it;
// Invert mirrors the tilt; Strength blends; and a render of a floor bumped by a ramp image under a
// point lamp gives the closed form of the tilted Lambert floor. Over a footprint (Cycles before
// 4.4) the heights are differenced along Cycles' axes a footprint apart: next to a kink of the
// height the normal tilts by the known forward difference where the slope at the point is zero.
#include "materials/normal_map.h"
#include "render/normal_mapping.h"
#include "render/renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "render_fixtures.h"

using namespace toyrt;
using namespace toyrt::testing;

namespace {

constexpr double kPiD = 3.14159265358979323846;

void expect_near(const Vec3& a, const Vec3& b, float eps = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, eps);
  EXPECT_NEAR(a.y, b.y, eps);
  EXPECT_NEAR(a.z, b.z, eps);
}

MaterialNormalMap bump_of(float distance, float strength = 1.0f) {
  MaterialNormalMap map;
  map.texture = 0;
  map.bump = true;
  map.distance = distance;
  map.strength = strength;
  map.shadowing = BumpShadowing::None;
  map.lift = false;
  return map;
}

// A 2 m floor at z = 0, uv = ((x + 1) / 2, (y + 1) / 2), bumped by a 64-texel image flat up to
// texel 32's centre and rising after it (texel i = max(0, i - 32) / 63): bilinear, the height is
// kink_height(x) = max(0, 32 x - 0.5) / 63 per metre along x, its kink at x = 1 / 64.
constexpr double kKinkX = 1.0 / 64.0, kKinkSlope = 32.0 / 63.0;
double kink_height(double x) { return std::max(0.0, kKinkSlope * (x - kKinkX)); }

// The kinked surface as material 0 of `scene`, placed by `to_world`, seen by the rays `visibility` names.
void add_kinked_surface(Scene& scene, MaterialNormalMap map, const Mat4& to_world = Mat4(1.0f),
                        uint8_t visibility = kVisibleAll) {
  std::vector<float> texels(64 * 3);
  for (int i = 0; i < 64; ++i)
    texels[size_t(3 * i)] = texels[size_t(3 * i + 1)] = texels[size_t(3 * i + 2)] = std::max(0, i - 32) / 63.0f;
  map.texture = int32_t(scene.add_texture(Texture::from_floats(64, 1, 3, texels, ColorEncoding::Linear)));
  scene.add_material(Lambert{Vec3(0.5f), -1}, {}, {}, map);
  MeshShading sh;
  sh.material_ids = {0, 0};
  sh.corner_uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 0}, {1, 1}, {0, 1}};
  scene.add_instance(scene.add_mesh({{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, {{0, 1, 2}, {0, 2, 3}}, sh),
                     to_world, true, 0, 0, visibility);
}

Scene kinked_floor(const MaterialNormalMap& map) {
  Scene scene;
  add_kinked_surface(scene, map);
  return scene;
}

// The normal Cycles 3.x gives the kinked floor at x over a footprint w, seen from above: its axes
// around Ng = +z are a = (1, -1, 0) / sqrt 2 and b = (1, 1, 0) / sqrt 2, both w / sqrt 2 along x,
// so h_x = h_y = dh = h(x + w / sqrt 2) - h(x), and N' = normalize(w^2 z - distance dh w (a + b)):
// the slope sqrt 2 dh / w along x.
Vec3 footprint_normal(double x, double w, double distance) {
  const double dh = kink_height(x + w / std::sqrt(2.0)) - kink_height(x);
  return glm::normalize(Vec3(float(-distance * std::sqrt(2.0) * dh / w), 0.0f, 1.0f));
}

}  // namespace

TEST(BumpMap, ALinearHeightTiltsTheNormalByItsSlopeWhateverTheTangentVectors) {
  // h = a x over the plane z = 0: the normal is normalize(-distance a, 0, 1) for any two tangent
  // vectors (of either orientation, any lengths), since the heights' changes follow them.
  const float a = 0.8f, distance = 0.5f;
  const Vec3 n(0, 0, 1), expected = glm::normalize(Vec3(-distance * a, 0.0f, 1.0f));
  const Vec3 bases[][2] = {
      {{1, 0, 0}, {0, 1, 0}}, {{2, 1, 0}, {-1, 3, 0}}, {{0, 1, 0}, {1, 0, 0}}, {{0.01f, 0, 0}, {0.003f, -0.02f, 0}}};
  for (const auto& b : bases)
    expect_near(bump_normal(bump_of(distance), n, b[0], b[1], a * b[0].x, a * b[1].x), expected);
  // Invert (a negative distance) mirrors the tilt; a flat height leaves n.
  expect_near(bump_normal(bump_of(-distance), n, bases[1][0], bases[1][1], a * 2.0f, a * -1.0f),
              glm::normalize(Vec3(distance * a, 0.0f, 1.0f)));
  expect_near(bump_normal(bump_of(distance), n, bases[1][0], bases[1][1], 0.0f, 0.0f), n);
}

TEST(BumpMap, StrengthBlendsTheBumpedNormalWithTheSmoothOne) {
  const MaterialNormalMap map = bump_of(1.0f, 0.25f);
  const Vec3 n(0, 0, 1), bent = bump_normal(map, n, Vec3(1, 0, 0), Vec3(0, 1, 0), 2.0f, 0.0f);
  expect_near(blend_normal_strength(map, bent, n), glm::normalize(n + 0.25f * (bent - n)));
}

TEST(BumpMap, AFloorBumpedByARampImageIsLitAsTheTiltedFloor) {
  // A 2 m floor, uv = ((x + 1) / 2, (y + 1) / 2), its height a 64-texel ramp (texel i = i / 63:
  // bilinear, h = (64 u - 0.5) / 63 between the first and last texel centres), Distance 0.5:
  // slope 0.5 x 64 / 63 x 1/2 per metre along x. Under a point lamp 1 m above the centre the
  // pixel is albedo / pi x P / (4 pi) x cos, cos = 1 / sqrt(1 + slope^2).
  std::vector<float> ramp(64 * 3);
  for (int i = 0; i < 64; ++i) ramp[size_t(3 * i)] = ramp[size_t(3 * i + 1)] = ramp[size_t(3 * i + 2)] = i / 63.0f;
  const float power = 100.0f;
  for (float strength : {1.0f, 0.5f}) {
    Scene scene;
    MaterialNormalMap map = bump_of(0.5f, strength);
    map.texture = int32_t(scene.add_texture(Texture::from_floats(64, 1, 3, ramp, ColorEncoding::Linear)));
    scene.add_material(Lambert{Vec3(0.5f), -1}, {}, {}, map);
    MeshShading sh;
    sh.material_ids = {0, 0};
    sh.corner_uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 0}, {1, 1}, {0, 1}};
    scene.add_instance(scene.add_mesh({{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, {{0, 1, 2}, {0, 2, 3}}, sh),
                       Mat4(1.0f));
    scene.add_light(PointLight::make(Vec3(0.0f, 0.0f, 1.0f), power, Vec3(1.0f)));
    scene.commit();
    const double slope = 0.5 * 64.0 / 63.0 * 0.5;
    const Vec3 up(0, 0, 1), full = glm::normalize(Vec3(float(-slope), 0.0f, 1.0f));
    const double cos = glm::dot(glm::normalize(up + strength * (full - up)), up);
    const double expected = 0.5 / kPiD * power / (4.0 * kPiD) * cos;
    EXPECT_NEAR(render(scene, pixel_above(1e-3f), few_samples(4)).rgba[0], expected, 1e-4 * expected) << strength;
  }
}

TEST(BumpMap, OverAFootprintTheHeightIsDifferencedAlongCyclesAxes) {
  MaterialNormalMap map = bump_of(0.5f);
  map.bump_footprint = true;
  const Scene scene = kinked_floor(map);
  const Vec3 up(0, 0, 1);
  const float w = 0.02f;
  // The hit at (x, -0.5) on triangle 0 ((-1,-1), (1,-1), (1,1)): v = (y + 1) / 2, u = (x + 1) / 2 - v.
  auto normal_at = [&](float x, float footprint) {
    Hit hit;
    hit.prim = 0;
    hit.instance = 0;
    hit.v = 0.25f;
    hit.u = (x + 1.0f) / 2.0f - hit.v;
    return normal_mapped(scene, hit, 0, up, up, up, Vec2((x + 1.0f) / 2.0f, 0.25f), footprint);
  };
  // Before the kink, closer than w / sqrt 2: flat at the point, tilted by the forward difference.
  const float before = float(kKinkX) - 0.005f;
  expect_near(normal_at(before, w), footprint_normal(before, w, 0.5), 1e-4f);
  EXPECT_LT(normal_at(before, w).z, 0.99f);  // a real tilt: slope 0.16
  // A zero footprint, or the slope at the point: flat there.
  expect_near(normal_at(before, 0.0f), up);
  map.bump_footprint = false;
  const Scene point = kinked_floor(map);
  Hit hit;
  hit.prim = 0;
  hit.instance = 0;
  hit.v = 0.25f;
  hit.u = (before + 1.0f) / 2.0f - hit.v;
  expect_near(normal_mapped(point, hit, 0, up, up, up, Vec2((before + 1.0f) / 2.0f, 0.25f), w), up);
  // On the ramp, where the height is linear over the footprint, both give the slope.
  expect_near(normal_at(0.3f, w), glm::normalize(Vec3(float(-0.5 * kKinkSlope), 0.0f, 1.0f)), 1e-4f);
}

TEST(BumpMap, AnOrthographicPixelsFootprintIsItsWidth) {
  // One 2 cm pixel of an orthographic camera above the origin, over the kinked floor (Distance 2)
  // under a point lamp 1 m above the origin: Cycles 3.x's footprint is the pixel's width w, so
  // the pixel's right part (x > 1/64 - w / sqrt 2) tilts (footprint_normal) though the whole pixel
  // is flat at the point. The closed form, integrated over the pixel by the midpoint rule:
  // albedo / pi x P / (4 pi) x max(0, N'(x) . (-x, -y, 1)) / r^3.
  const float w = 0.02f, power = 100.0f;
  double sum = 0.0;
  const int n = 400;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double x = w * ((i + 0.5) / n - 0.5), y = w * ((j + 0.5) / n - 0.5);
      const Vec3 nb = footprint_normal(x, w, 2.0);
      const double r = std::sqrt(x * x + y * y + 1.0);
      sum += std::max(0.0, -nb.x * x - nb.y * y + nb.z) / (r * r * r);
    }
  const double expected = 0.5 / kPiD * power / (4.0 * kPiD) * sum / (n * n);
  MaterialNormalMap map = bump_of(2.0f);
  map.bump_footprint = true;
  Scene scene = kinked_floor(map);
  scene.add_light(PointLight::make(Vec3(0.0f, 0.0f, 1.0f), power, Vec3(1.0f)));
  scene.commit();
  const double rendered = render(scene, pixel_above(w), few_samples(1024)).rgba[0];
  EXPECT_NEAR(rendered, expected, 1e-3 * expected);
  // The flat floor's value, which the slope at the point gives, is clearly apart.
  map.bump_footprint = false;
  Scene point = kinked_floor(map);
  point.add_light(PointLight::make(Vec3(0.0f, 0.0f, 1.0f), power, Vec3(1.0f)));
  point.commit();
  const double flat = render(point, pixel_above(w), few_samples(1024)).rgba[0];
  EXPECT_GT(flat - rendered, 0.01 * expected);
}

TEST(BumpMap, AReflectedRayKeepsTheFootprintItStartedWith) {
  // Cycles 3.x starts a reflected ray with the hit's width. The orthographic 2 cm pixel sees a
  // sharp mirror at z = 0 that shows the kinked surface as a ceiling at z = 1 (hidden from camera
  // rays), lit by a point lamp at (0.5, 0, 0.5), off the mirror's direction. At the ceiling Ng on the ray's side is -z,
  // whose axes are a = (-1, 1, 0) / sqrt 2, b = (1, 1, 0) / sqrt 2: before the kink h_x = 0 (a looks back, into the
  // flat part) and h_y = dh = h(x + w / sqrt 2) - h(x), so N' = normalize(-z - Distance dh / w b). The ceiling's
  // radiance, integrated over the pixel: albedo / pi x P / (4 pi) x max(0, N' . l) / r^2, l towards the lamp.
  const float w = 0.02f, power = 100.0f, distance = 2.0f;
  double sum = 0.0;
  const int n = 400;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double x = w * ((i + 0.5) / n - 0.5), y = w * ((j + 0.5) / n - 0.5);
      const double t = distance * (kink_height(x + w / std::sqrt(2.0)) - kink_height(x)) / (w * std::sqrt(2.0));
      const double len = std::sqrt(2.0 * t * t + 1.0), r = std::sqrt((0.5 - x) * (0.5 - x) + y * y + 0.25);
      // N' = (-t, -t, -1) / len, l = (0.5 - x, -y, -0.5) / r.
      sum += std::max(0.0, (-t * (0.5 - x) + t * y + 0.5) / (len * r)) / (r * r);
    }
  const double expected = 0.5 / kPiD * power / (4.0 * kPiD) * sum / (n * n);
  for (bool footprint : {true, false}) {
    MaterialNormalMap map = bump_of(distance);
    map.bump_footprint = footprint;
    Scene ceiling;
    add_kinked_surface(ceiling, map, glm::translate(Mat4(1.0f), Vec3(0.0f, 0.0f, 1.0f)),
                       uint8_t(kVisibleAll & ~kVisibleCamera));
    ceiling.add_material(Glossy::make(Vec3(1.0f), 0.0f, GgxShadowing::Separable));
    MeshShading mirror;
    mirror.material_ids = {1, 1};
    ceiling.add_instance(
        ceiling.add_mesh({{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, {{0, 1, 2}, {0, 2, 3}}, mirror), Mat4(1.0f));
    ceiling.add_light(PointLight::make(Vec3(0.5f, 0.0f, 0.5f), power, Vec3(1.0f)));
    ceiling.commit();
    const double rendered = render(ceiling, pixel_above(w), few_samples(1024)).rgba[0];
    if (footprint)
      EXPECT_NEAR(rendered, expected, 1e-3 * expected);
    else  // the slope at the point: the flat ceiling, clearly apart
      EXPECT_GT(std::fabs(rendered - expected), 0.01 * expected);
  }
}

TEST(BumpMap, ItsKeywordsAreReadAndMistakesRefused) {
  Params p;
  p.set("bump_map", 2.0);
  p.set("bump_distance", -0.25);
  p.set("bump_channel", std::string("alpha"));
  const MaterialNormalMap map = MaterialNormalMap::from_params(p);
  EXPECT_TRUE(map.bump && map.bump_alpha && map.active());
  EXPECT_EQ(map.texture, 2);
  EXPECT_FLOAT_EQ(map.distance, -0.25f);
  Params both;
  both.set("bump_map", 0.0);
  both.set("normal_map", 1.0);
  EXPECT_THROW(MaterialNormalMap::from_params(both), std::invalid_argument);
  Params channel;
  channel.set("bump_map", 0.0);
  channel.set("bump_channel", std::string("red"));
  EXPECT_THROW(MaterialNormalMap::from_params(channel), std::invalid_argument);
  EXPECT_FALSE(map.bump_footprint);  // the slope at the point unless asked
  Params footprint;
  footprint.set("bump_map", 0.0);
  footprint.set("bump_footprint", std::string("pixel"));
  EXPECT_TRUE(MaterialNormalMap::from_params(footprint).bump_footprint);
  footprint.set("bump_footprint", std::string("wide"));
  EXPECT_THROW(MaterialNormalMap::from_params(footprint), std::invalid_argument);
  MaterialNormalMap bad = bump_of(NAN);
  EXPECT_THROW(bad.check(1), std::invalid_argument);
}
