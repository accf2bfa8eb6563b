// The Bump node's normal (materials/normal_map.h, render/normal_mapping.cpp): a height that rises
// linearly tilts the normal by its slope times Distance, whatever tangent vectors measure it;
// Invert mirrors the tilt; Strength blends; and a render of a floor bumped by a ramp image under a
// point lamp gives the closed form of the tilted Lambert floor.
#include "materials/normal_map.h"
#include "render/renderer.h"

#include <gtest/gtest.h>

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
  MaterialNormalMap bad = bump_of(NAN);
  EXPECT_THROW(bad.check(1), std::invalid_argument);
}
