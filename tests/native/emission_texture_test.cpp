// Emission whose colour is an image (materials/emission.h): seen directly, the image's texel times
// the strength; as a light, the irradiance of the part of the emitter the image lights, whether
// the triangle is chosen by the power CDF or the light tree and sampled by area or solid angle.
#include "render/renderer.h"

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <vector>

#include "render_fixtures.h"
#include "test_scenes.h"

using namespace toyrt;
using namespace toyrt::testing;

namespace {

constexpr double kPiD = 3.14159265358979323846;

// An image 64 texels wide and one high: white in columns 16-47, black elsewhere. Over u it lights
// [0.25, 0.75] (the bilinear ramps around both edges are symmetric, so they integrate to the step).
Texture band_image() {
  std::vector<float> px(64 * 3, 0.0f);
  for (int i = 16; i < 48; ++i) px[size_t(3 * i)] = px[size_t(3 * i + 1)] = px[size_t(3 * i + 2)] = 1.0f;
  return Texture::from_floats(64, 1, 3, px, ColorEncoding::Linear);
}

// An emitting square [-1, 1]^2 at height z, `side` x `side` quads, uv = ((x + 1) / 2, (y + 1) / 2).
void add_square(Scene& scene, float z, int side, int32_t material) {
  const GridData g = square_grid(side, 0.0f, z, 1.0f);
  MeshShading sh;
  sh.material_ids.assign(g.mesh.triangles.size(), material);
  for (const Triangle& tri : g.mesh.triangles)
    for (uint32_t k : {tri.x, tri.y, tri.z}) sh.corner_uvs.push_back(g.uvs[k]);
  scene.add_instance(scene.add_mesh(g.mesh.vertices, g.mesh.triangles, sh), Mat4(1.0f));
}

// One pixel of an orthographic camera at (x, 0, z) looking down.
Camera pixel_at(float x, float z) {
  CameraParams p;
  p.type = CameraType::Orthographic;
  p.ortho_scale = 1e-3f;
  p.resolution_x = p.resolution_y = 1;
  p.matrix_world = glm::translate(Mat4(1.0f), Vec3(x, 0.0f, z));
  return Camera::make(p);
}

// Howell's C-11: the form factor from a point to a parallel rectangle of sides a, b with one
// corner above it, at height h.
double corner_factor(double a, double b, double h) {
  const double x = a / h, y = b / h;
  return (x / std::sqrt(1 + x * x) * std::atan(y / std::sqrt(1 + x * x)) +
          y / std::sqrt(1 + y * y) * std::atan(x / std::sqrt(1 + y * y))) /
         (2.0 * kPiD);
}

}  // namespace

TEST(EmissionTexture, SeenDirectlyItIsTheTexelTimesTheStrength) {
  Scene scene;
  const int32_t image = int32_t(scene.add_texture(band_image()));
  MaterialEmission glow;
  glow.radiance = Vec3(3.0f);
  glow.texture = image;
  add_square(scene, 1.0f, 1, int32_t(scene.add_material(Lambert{Vec3(0.0f), -1}, glow)));
  scene.commit();
  // x = -0.25: u = 0.375, inside the white band; x = -0.75: u = 0.125, black.
  EXPECT_NEAR(render(scene, pixel_at(-0.25f, 5.0f), few_samples(4)).rgba[0], 3.0f, 1e-5f);
  EXPECT_EQ(render(scene, pixel_at(-0.75f, 5.0f), few_samples(4)).rgba[0], 0.0f);
}

TEST(EmissionTexture, AnImageOfOneColourLightsAsThatConstantColour) {
  // The same triangles, the same weights (the estimate of a uniform image is its colour), so the
  // same samples: the pixels agree to rounding.
  const Vec3 color(0.25f, 0.5f, 0.75f);
  float pixel[2][3];
  for (int textured = 0; textured < 2; ++textured) {
    Scene scene = floor_of(Lambert{Vec3(0.5f), -1});
    MaterialEmission glow;
    if (textured) {
      const std::vector<float> px = {color.x, color.y, color.z, color.x, color.y, color.z,
                                     color.x, color.y, color.z, color.x, color.y, color.z};
      glow.texture = int32_t(scene.add_texture(Texture::from_floats(2, 2, 3, px, ColorEncoding::Linear)));
      glow.radiance = Vec3(4.0f);
    } else {
      glow.radiance = 4.0f * color;
    }
    add_square(scene, 1.0f, 4, int32_t(scene.add_material(Lambert{Vec3(0.0f), -1}, glow)));
    scene.commit();
    const RenderResult r = render(scene, pixel_at(0.1f, 0.5f), few_samples(256));
    for (int c = 0; c < 3; ++c) pixel[textured][c] = r.rgba[size_t(c)];
  }
  for (int c = 0; c < 3; ++c) {
    EXPECT_GT(pixel[0][c], 0.0f);
    EXPECT_NEAR(pixel[1][c], pixel[0][c], 1e-5f * pixel[0][c]) << c;
  }
}

TEST(EmissionTexture, ALitBandOfTheImageGivesTheBandsIrradiance) {
  // The square lights only x in [-0.5, 0.5]: under its centre a floor of albedo 0.5 shows
  // 0.5 L x 4 F(0.5, 1, h). Close (h = 1) the triangles are sampled by solid angle, far (h = 4)
  // by area; as 2 triangles by the power CDF, as 128 through the light tree (most of them over
  // black, weighed low but not 0).
  const float strength = 6.0f;
  for (float h : {1.0f, 4.0f})
    for (int side : {1, 8}) {
      Scene scene = floor_of(Lambert{Vec3(0.5f), -1});
      MaterialEmission glow;
      glow.radiance = Vec3(strength);
      glow.texture = int32_t(scene.add_texture(band_image()));
      add_square(scene, h, side, int32_t(scene.add_material(Lambert{Vec3(0.0f), -1}, glow)));
      scene.set_emitter_tree_from(kEmitterTreeFrom, 0.0f);
      scene.commit();
      EXPECT_EQ(scene.commit_stats().emitter_tree_nodes > 0, side > 1);
      const double expected = 0.5 * strength * 4.0 * corner_factor(0.5, 1.0, h);
      const double got = render(scene, pixel_at(0.0f, 0.5f), few_samples(8192)).rgba[0];
      EXPECT_NEAR(got, expected, 0.01 * expected) << "h " << h << ", " << 2 * side * side << " triangles";
    }
}

TEST(EmissionTexture, AnUnknownTextureIdIsRefused) {
  Scene scene;
  MaterialEmission glow;
  glow.radiance = Vec3(1.0f);
  glow.texture = 0;  // the scene has none
  EXPECT_THROW(scene.add_material(Lambert{Vec3(0.0f), -1}, glow), std::invalid_argument);
  EXPECT_EQ(scene.materials().size(), 0u);
}
