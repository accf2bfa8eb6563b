// Cut-outs (materials/transparency.h, render/transparent_walk.h): closed forms of a floor under a
// point light seen past, or shadowed by, surfaces with a transparent part, and Cycles' limits on
// how many such surfaces paths and shadow rays pass (transparent_max_bounces).
#include "materials/transparency.h"
#include "render/renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "render_fixtures.h"

using namespace toyrt;
using namespace toyrt::testing;

namespace {

constexpr double kPiD = 3.14159265358979323846;
constexpr float kPower = 100.0f;

// A 0.2 m square at height z centred on (x, 0) with material `material`.
void add_quad(Scene& scene, float x, float z, int32_t material, float half = 0.1f) {
  MeshShading sh;
  sh.material_ids = {material, material};
  sh.corner_uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 0}, {1, 1}, {0, 1}};
  scene.add_instance(
      scene.add_mesh({{x - half, -half, z}, {x + half, -half, z}, {x + half, half, z}, {x - half, half, z}},
                     {{0, 1, 2}, {0, 2, 3}}, sh),
      Mat4(1.0f));
}

MaterialTransparency cut_out(float opacity, Vec3 color = Vec3(1.0f)) {
  MaterialTransparency t;
  t.opacity = opacity;
  t.color = color;
  return t;
}

// The floor (albedo 0.5) under the camera's pixel at the origin, lit by a point light at (1, 0, 1)
// past quads at heights `heights` on the way (x = z), each of `t`.
RenderResult floor_past_quads(const MaterialTransparency& t, std::initializer_list<float> heights, int budget) {
  Scene scene = floor_of(Lambert{Vec3(0.5f), -1});
  const uint32_t m = scene.add_material(Lambert{}, {}, t);
  for (float z : heights) add_quad(scene, z, z, int32_t(m), 0.05f);
  scene.add_light(PointLight::make(Vec3(1.0f, 0.0f, 1.0f), kPower, Vec3(1.0f)));
  scene.commit();
  RenderSettings settings = few_samples(4);
  settings.integrator.transparent_max_bounces = budget;
  return render(scene, pixel_above(1e-3f), settings);
}

// The open floor's pixel under the light at (1, 0, 1): cos 45 degrees over r^2 = 2.
const double kOpenFloor = 0.5 / kPiD * kPower / (4.0 * kPiD) * (1.0 / std::sqrt(2.0)) / 2.0;

}  // namespace

TEST(Transparency, ShadowThroughAQuadOfOpacityAIsOneMinusATimesItsColourTimesTheOpenFloor) {
  const Vec3 color(1.0f, 0.5f, 0.25f);
  const RenderResult r = floor_past_quads(cut_out(0.3f, color), {0.5f}, 8);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.rgba[c], kOpenFloor * 0.7 * color[c], 1e-4 * kOpenFloor) << c;
}

TEST(Transparency, AShadowRayPassesAtMostTransparentMaxBouncesSurfacesThenIsBlocked) {
  const float a = 0.25f;
  const double three = kOpenFloor * std::pow(1.0 - a, 3);
  EXPECT_NEAR(floor_past_quads(cut_out(a), {0.3f, 0.5f, 0.7f}, 3).rgba[0], three, 1e-4 * three);
  EXPECT_EQ(floor_past_quads(cut_out(a), {0.3f, 0.5f, 0.7f}, 2).rgba[0], 0.0f);
  EXPECT_EQ(floor_past_quads(cut_out(0.0f), {0.5f}, 0).rgba[0], 0.0f);
}

TEST(Transparency, AnOpaqueMaterialCastsAFullShadowAndASceneWithoutCutOutsKeepsTheAnyHitQuery) {
  Scene scene = floor_of(Lambert{Vec3(0.5f), -1});
  EXPECT_FALSE(scene.any_transparency());
  const uint32_t m = scene.add_material(Lambert{}, {}, cut_out(1.0f));
  EXPECT_FALSE(scene.any_transparency());  // opacity 1, no texture: opaque
  scene.set_material(m, Lambert{}, {}, cut_out(0.5f));
  EXPECT_TRUE(scene.any_transparency());
  scene.set_material(m, Lambert{}, {}, cut_out(1.0f));
  EXPECT_FALSE(scene.any_transparency());
  EXPECT_EQ(floor_past_quads(cut_out(1.0f), {0.5f}, 8).rgba[0], 0.0f);
}

// The camera looks down at a quad (albedo 0.8, opacity a) 1 m above the floor, the light 1 m
// above the quad: the pixel is a x the quad's radiance + (1 - a) x the floor's, itself in the
// quad's shadow of transmittance 1 - a.
TEST(Transparency, ACameraRaySeesOpacityTimesTheSurfacePlusTheRestTimesWhatIsBehind) {
  for (float a : {0.0f, 0.4f, 1.0f}) {
    Scene scene = floor_of(Lambert{Vec3(0.5f), -1});
    const uint32_t m = scene.add_material(Lambert{Vec3(0.8f), -1}, {}, cut_out(a));
    add_quad(scene, 0.0f, 1.0f, int32_t(m));
    scene.add_light(PointLight::make(Vec3(0.0f, 0.0f, 2.0f), kPower, Vec3(1.0f)));
    scene.commit();
    const double quad = 0.8 / kPiD * kPower / (4.0 * kPiD);
    const double floor = 0.5 / kPiD * kPower / (4.0 * kPiD * 4.0) * (1.0 - a);
    const double expected = a * quad + (1.0 - a) * floor;
    const RenderResult r = render(scene, pixel_above(1e-3f), few_samples(1024));
    EXPECT_NEAR(r.rgba[0], expected, 2e-3 * expected) << a;
    EXPECT_EQ(r.rgba[3], 1.0f);
  }
}

// Cycles: a path that has passed transparent_max_bounces transparent surfaces stops at the next
// surface (it shows that surface's emission only): the floor behind one fully transparent quad
// is black with a limit of 1 and lit with 2.
TEST(Transparency, APathPastTransparentMaxBouncesShadesNothingAtTheNextSurface) {
  for (int budget : {1, 2}) {
    Scene scene = floor_of(Lambert{Vec3(0.5f), -1});
    const uint32_t m = scene.add_material(Lambert{}, {}, cut_out(0.0f));
    add_quad(scene, 0.0f, 1.0f, int32_t(m));
    scene.add_light(PointLight::make(Vec3(0.0f, 0.0f, 2.0f), kPower, Vec3(1.0f)));
    scene.commit();
    RenderSettings settings = few_samples(4);
    settings.integrator.transparent_max_bounces = budget;
    const RenderResult r = render(scene, pixel_above(1e-3f), settings);
    const double lit = 0.5 / kPiD * kPower / (4.0 * kPiD * 4.0);
    if (budget == 1)
      EXPECT_EQ(r.rgba[0], 0.0f);
    else
      EXPECT_NEAR(r.rgba[0], lit, 1e-4 * lit);
  }
}

TEST(Transparency, OpacityIsClampedNaNIsOpaqueAndATextureChannelIsRead) {
  const std::vector<Texture> none;
  EXPECT_EQ(cut_out(1.5f).opacity_at(none, Vec2(0.0f)), 1.0f);
  EXPECT_EQ(cut_out(-0.5f).opacity_at(none, Vec2(0.0f)), 0.0f);
  EXPECT_EQ(cut_out(std::numeric_limits<float>::quiet_NaN()).opacity_at(none, Vec2(0.0f)), 1.0f);
  const std::vector<Texture> one{Texture::from_floats(1, 1, 4, {0.2f, 0.4f, 0.6f, 0.3f}, ColorEncoding::Linear)};
  MaterialTransparency t;
  t.texture = 0;
  EXPECT_FLOAT_EQ(t.opacity_at(one, Vec2(0.5f)), 0.3f);
  t.invert = true;
  EXPECT_FLOAT_EQ(t.opacity_at(one, Vec2(0.5f)), 0.7f);
  t.invert = false;
  t.channel = OpacityChannel::Gray;  // Rec. 709 luminance, as Blender's colour-to-float
  EXPECT_NEAR(t.opacity_at(one, Vec2(0.5f)), 0.2126 * 0.2 + 0.7152 * 0.4 + 0.0722 * 0.6, 1e-6);
}

TEST(Transparency, RefusesAnUnknownOpacityTextureAndANegativeColour) {
  Scene scene;
  MaterialTransparency t;
  t.texture = 0;
  EXPECT_THROW(scene.add_material(Lambert{}, {}, t), std::invalid_argument);
  EXPECT_THROW(scene.add_material(Lambert{}, {}, cut_out(0.5f, Vec3(-1.0f))), std::invalid_argument);
}

// An emissive square beside the camera's pixel lights the floor through a fully transparent cut-out
// of colour C that covers both: the camera ray passes it once and the light, by both strategies
// (the shadow ray to the emitter and the cosine ray that finds it), once more, so the pixel is
// C^2 times the pixel without the cut-out.
TEST(Transparency, AnEmitterBehindACutOutLightsThroughItByBothStrategies) {
  double pixel[2];
  for (int with_cut_out = 0; with_cut_out < 2; ++with_cut_out) {
    Scene scene = floor_of(Lambert{Vec3(0.5f), -1});
    MaterialEmission glow;
    glow.radiance = Vec3(20.0f);
    const uint32_t lamp = scene.add_material(Lambert{Vec3(0.0f), -1}, glow);
    add_quad(scene, 0.6f, 1.0f, int32_t(lamp), 0.3f);
    if (with_cut_out)
      add_quad(scene, 0.0f, 0.5f, int32_t(scene.add_material(Lambert{}, {}, cut_out(0.0f, Vec3(0.5f)))), 2.0f);
    scene.commit();
    pixel[with_cut_out] = render(scene, pixel_above(1e-3f), few_samples(4096)).rgba[0];
  }
  EXPECT_GT(pixel[0], 0.0);
  EXPECT_NEAR(pixel[1] / pixel[0], 0.25, 0.01);
}

// A crossing keeps the ray's kind, as in Cycles: a camera ray through a Transparent BSDF of colour
// C still sees the world as a camera ray (C x background), and sees black when the world is hidden
// from the camera.
TEST(Transparency, ACameraRayThroughACutOutIsStillACameraRay) {
  for (bool visible : {true, false}) {
    Scene scene;
    const uint32_t m = scene.add_material(Lambert{}, {}, cut_out(0.0f, Vec3(0.5f, 0.25f, 1.0f)));
    add_quad(scene, 0.0f, 1.0f, int32_t(m));
    scene.set_background(Vec3(0.3f));
    scene.set_background_visible_camera(visible);
    scene.commit();
    const RenderResult r = render(scene, pixel_above(1e-3f), few_samples(4));
    EXPECT_FLOAT_EQ(r.rgba[0], visible ? 0.15f : 0.0f);
    EXPECT_FLOAT_EQ(r.rgba[1], visible ? 0.075f : 0.0f);
  }
}
