// The glossy transport end to end, against closed forms built from the lobe itself: a glossy
// floor seen from straight above, in a uniform background of radiance 1, shows its directional
// albedo (the continuation ray escapes with weight G2 / G1); under a small spherical lamp it shows
// f(z, z) I / d^2, whether the lamp is a delta (light sampling alone) or has a radius (light
// sampling and the continuation ray combined by MIS: wrong weights double or lose the light).
#include "materials/material.h"
#include "render/renderer.h"
#include "render_fixtures.h"
#include "sampling/ggx.h"

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include <cmath>

using namespace toyrt;
using namespace toyrt::testing;

namespace {

constexpr double kPiD = 3.14159265358979323846;

Scene glossy_floor(float roughness, GgxShadowing shadowing) {
  return floor_of(Glossy::make(Vec3(1.0f), roughness, shadowing));
}

// The lobe's directional albedo at normal incidence, by quadrature.
double albedo_at_normal_incidence(float alpha, GgxShadowing shadowing) {
  const int nt = 2048, np = 64;
  double sum = 0.0;
  const Vec3 wo(0.0f, 0.0f, 1.0f);
  for (int i = 0; i < nt; ++i) {
    const double t = (i + 0.5) * 0.5 * kPiD / nt;
    for (int j = 0; j < np; ++j) {
      const double p = (j + 0.5) * 2.0 * kPiD / np;
      const Vec3 wi(float(std::sin(t) * std::cos(p)), float(std::sin(t) * std::sin(p)), float(std::cos(t)));
      sum += ggx_reflection_eval(alpha, shadowing, wo, wi).f * std::cos(t) * std::sin(t) * (0.5 * kPiD / nt) *
             (2.0 * kPiD / np);
    }
  }
  return sum;
}

}  // namespace

TEST(GlossyRender, FloorInAUniformBackgroundShowsItsDirectionalAlbedo) {
  for (float roughness : {0.3f, 1.0f}) {
    for (GgxShadowing shadowing : {GgxShadowing::Separable, GgxShadowing::HeightCorrelated}) {
      Scene scene = glossy_floor(roughness, shadowing);
      scene.set_background(Vec3(1.0f));
      scene.commit();
      const RenderResult r = render(scene, pixel_above(), few_samples(4096));
      const double expected = albedo_at_normal_incidence(ggx_alpha(roughness), shadowing);
      EXPECT_NEAR(r.rgba[0], expected, 5e-3) << "roughness " << roughness;
      EXPECT_LT(expected, 1.0);
    }
  }
}

TEST(GlossyRender, FloorUnderASmallLampIsItsBrdfTimesTheIrradiance) {
  const float power = 100.0f;
  for (float radius : {0.0f, 0.03f}) {
    Scene scene = glossy_floor(1.0f, GgxShadowing::Separable);
    LightVisibility hidden;
    hidden.camera = false;  // the lamp is between the camera and the floor
    scene.add_light(PointLight::make(Vec3(0.0f, 0.0f, 1.0f), power, Vec3(1.0f), radius), hidden);
    scene.commit();
    const RenderResult r = render(scene, pixel_above(), few_samples(1024));
    const Vec3 z(0.0f, 0.0f, 1.0f);
    // I / d^2 at d = 1 m; over the lamp's 0.03 rad the rough lobe's value changes by < 0.1 %.
    const double expected = ggx_reflection_eval(1.0f, GgxShadowing::Separable, z, z).f * power / (4.0 * kPiD);
    EXPECT_NEAR(r.rgba[0], expected, 1e-2 * expected) << "radius " << radius;
  }
}

TEST(GlossyRender, SharpFloorReflectsTheLampWithoutNaN) {
  // Roughness 0 (alpha at its floor): the lamp is a tiny, very bright highlight, found by the
  // continuation ray; MIS must keep every sample finite.
  Scene scene = glossy_floor(0.0f, GgxShadowing::Separable);
  LightVisibility hidden;
  hidden.camera = false;
  scene.add_light(PointLight::make(Vec3(0.0f, 0.0f, 1.0f), 100.0f, Vec3(1.0f), 0.1f), hidden);
  scene.commit();
  const RenderResult r = render(scene, pixel_above(), few_samples(64));
  EXPECT_TRUE(std::isfinite(r.rgba[0]));
  // A mirror under a disc of radiance L that fills the reflected direction shows L.
  const double lamp_radiance = 100.0 / (4.0 * kPiD) / (kPiD * 0.1 * 0.1);
  EXPECT_NEAR(r.rgba[0], lamp_radiance, 2e-2 * lamp_radiance);
}

TEST(GlossyRender, DiffuseAndGlossySideBySideAddTheirLight) {
  // A Mix Shader of a Diffuse and a Glossy BSDF at factor 0.25 under a delta lamp 1 m above:
  // (0.75 albedo / pi + 0.25 colour / (4 pi)) I / d^2 at roughness 1, normal incidence.
  Params p;
  p.set("color", Vec3(0.5f)).set("diffuse_weight", 0.75).set("glossy_color", Vec3(0.25f)).set("roughness", 1.0);
  Scene scene = floor_of(make_material("diffuse_glossy", p));
  const float power = 100.0f;
  scene.add_light(PointLight::make(Vec3(0.0f, 0.0f, 1.0f), power, Vec3(1.0f)));
  scene.commit();
  const RenderResult r = render(scene, pixel_above(), few_samples(16));
  const double irradiance = power / (4.0 * kPiD);
  const double expected = (0.75 * 0.5 / kPiD + 0.25 / (4.0 * kPiD)) * irradiance;
  EXPECT_NEAR(r.rgba[0], expected, 1e-4 * expected);
}
