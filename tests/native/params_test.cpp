// Parameters as data (core/params.h) and the type tables they feed (make_light, make_material):
// a typo or a wrong type is refused by name, an unknown type lists the known ones, and a light
// or material made from parameters is the one built directly.
#include "core/params.h"
#include "lights/light.h"
#include "materials/material.h"

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include <stdexcept>
#include <string>

using namespace toyrt;

namespace {

// The message of the std::invalid_argument `f` throws ("" if none).
template <class F>
std::string refusal(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

void expect_same(const PointLight& a, const PointLight& b) {
  EXPECT_EQ(a.position, b.position);
  EXPECT_EQ(a.radius, b.radius);
  EXPECT_EQ(a.intensity, b.intensity);
  EXPECT_EQ(a.radiance, b.radiance);
}

void expect_same(const AreaLight& a, const AreaLight& b) {
  EXPECT_EQ(a.shape, b.shape);
  EXPECT_EQ(a.center, b.center);
  EXPECT_EQ(a.edge_x, b.edge_x);
  EXPECT_EQ(a.edge_y, b.edge_y);
  EXPECT_EQ(a.normal, b.normal);
  EXPECT_EQ(a.area, b.area);
  EXPECT_EQ(a.radiance, b.radiance);
  EXPECT_EQ(a.spread.active, b.spread.active);
  EXPECT_EQ(a.spread.tan_half, b.spread.tan_half);
}

}  // namespace

TEST(Params, UnknownArgumentIsNamed) {
  const Params typo({{"position", Vec3(0, 0, 1)}, {"powr", 100.0}});
  EXPECT_EQ(refusal([&] { make_light("POINT", typo); }), "unknown argument 'powr' for a POINT light");
  EXPECT_EQ(refusal([&] {
              make_material("glass", Params({{"iro", 1.5}}));
            }),
            "unknown argument 'iro' for a glass material");
}

TEST(Params, BadValueNamesTheTypeTheArgumentAndTheRequirement) {
  EXPECT_EQ(refusal([&] {
              make_light("POINT", Params({{"power", -1.0}}));
            }),
            "POINT light: power must be finite and >= 0, got -1");
  EXPECT_EQ(refusal([&] {
              make_light("AREA", Params({{"size", std::string("big")}}));
            }),
            "AREA light: size must be a number, got text");
  EXPECT_EQ(refusal([&] {
              make_material("diffuse", Params({{"color", Vec3(1, -1, 1)}}));
            }),
            "diffuse material: color must be finite and >= 0, got (1, -1, 1)");
  EXPECT_EQ(refusal([&] {
              make_material("refraction", Params({{"ior", 0.0}}));
            }),
            "refraction material: ior must be positive and finite, got 0");
}

TEST(Params, UnknownTypeListsTheKnownOnes) {
  EXPECT_EQ(refusal([] { make_light("HEMI", {}); }),
            "unknown light type 'HEMI': expected 'POINT', 'AREA', 'SPOT' or 'SUN'");
  EXPECT_EQ(refusal([] { make_material("metal", {}); }),
            "unknown material kind 'metal': expected 'diffuse', 'refraction', 'glass', 'glossy', 'diffuse_glossy' or "
            "'principled'");
}

TEST(Params, AllowedUnreadArgumentsPass) {
  Params p({{"color", Vec3(0.5f)}, {"texture", -1.0}, {"ior", 1.5}});
  EXPECT_NE(refusal([&] { make_material("glass", p); }), "");
  for (const char* shared : {"color", "texture", "ior"}) p.allow_unread(shared);
  EXPECT_EQ(std::get<FresnelDielectric>(make_material("glass", p)).ior, 1.5f);
  EXPECT_EQ(std::get<Lambert>(make_material("diffuse", p)).albedo, Vec3(0.5f));
}

TEST(MakeLight, EqualsTheLightBuiltDirectly) {
  const Light point = make_light(
      "POINT", Params({{"position", Vec3(1, 2, 3)}, {"power", 50.0}, {"color", Vec3(1, 0.5f, 0.2f)}, {"radius", 0.1}}));
  expect_same(std::get<PointLight>(point), PointLight::make(Vec3(1, 2, 3), 50.0f, Vec3(1, 0.5f, 0.2f), 0.1f));

  const Mat4 m = glm::rotate(glm::translate(Mat4(1.0f), Vec3(0, 1, 2)), 0.3f, Vec3(1, 0, 0));
  const Light area = make_light("AREA", Params({{"matrix", m},
                                                {"shape", std::string("RECTANGLE")},
                                                {"size", 0.5},
                                                {"size_y", 0.25},
                                                {"power", 30.0},
                                                {"color", Vec3(0.2f, 0.4f, 1.0f)},
                                                {"spread", 0.6}}));
  expect_same(std::get<AreaLight>(area),
              AreaLight::make(AreaShape::Rectangle, 0.5f, 0.25f, m, 30.0f, Vec3(0.2f, 0.4f, 1.0f), 0.6f));
}

TEST(MakeLight, DefaultsAreTheTypesSettings) {
  const PointLight::Settings p;
  expect_same(std::get<PointLight>(make_light("POINT", {})), PointLight::make(p.position, p.power, p.color, p.radius));
  const AreaLight::Settings a;
  expect_same(std::get<AreaLight>(make_light("AREA", {})),
              AreaLight::make(a.shape, a.size, a.size, a.matrix, a.power, a.color, a.spread));
}

TEST(MakeMaterial, EqualsTheMaterialBuiltDirectly) {
  const Material diffuse = make_material("diffuse", Params({{"color", Vec3(0.1f, 0.2f, 0.3f)}, {"texture", 2.0}}));
  EXPECT_EQ(std::get<Lambert>(diffuse).albedo, Vec3(0.1f, 0.2f, 0.3f));
  EXPECT_EQ(std::get<Lambert>(diffuse).texture, 2);
  EXPECT_EQ(std::get<PerfectRefraction>(make_material("refraction", Params({{"ior", 1.5}}))).ior,
            PerfectRefraction::make(1.5f).ior);
  EXPECT_EQ(std::get<FresnelDielectric>(make_material("glass", {})).ior, FresnelDielectric{}.ior);
  EXPECT_EQ(std::get<Lambert>(make_material("diffuse", {})).albedo, Lambert{}.albedo);
}
