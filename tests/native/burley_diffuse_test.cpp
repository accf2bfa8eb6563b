// Burley's diffuse (materials/burley_diffuse.h, Blender 3.x's Principled base) against known
// answers: Lambert exactly at roughness 0 and normal incidence; reciprocity; its directional
// albedo by quadrature against the closed forms of the factor's integrals (the Schlick weights
// integrate to Beta functions); and the Principled material handing it to the integrator on 3.x
// only.
#include "materials/burley_diffuse.h"
#include "hemisphere.h"
#include "materials/principled.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

using namespace toyrt;
using toyrt::testing::direction;
using toyrt::testing::hemisphere_integral;

namespace {

// The directional albedo at wo of a white Burley surface on the plane z = 0: the integral of
// factor / pi cos over the hemisphere.
double albedo(float roughness, const Vec3& wo) {
  const BurleyDiffuse b{Vec3(0, 0, 1), wo, roughness};
  return hemisphere_integral([&](const Vec3& wi) { return double(burley_factor(b, wi)) * wi.z / M_PI; }, 1024, 256);
}

}  // namespace

TEST(BurleyDiffuse, NormalIncidenceAtRoughnessZeroIsLambert) {
  const Vec3 n(0, 0, 1);
  EXPECT_FLOAT_EQ(burley_factor(BurleyDiffuse{n, n, 0.0f}, n), 1.0f);
  // Grazing on both sides: both Schlick weights are 1, each halving the value.
  const Vec3 grazing = glm::normalize(Vec3(1.0f, 0.0f, 0.0f));
  EXPECT_NEAR(burley_factor(BurleyDiffuse{n, grazing, 0.0f}, -grazing), 0.25f, 1e-6f);
  // At normal incidence both weights vanish: the retro-reflection term is 0 whatever the roughness.
  EXPECT_FLOAT_EQ(burley_factor(BurleyDiffuse{n, n, 1.0f}, n), 1.0f);
}

TEST(BurleyDiffuse, IsReciprocal) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 a = direction(std::acos(u(rng)), 2.0 * M_PI * u(rng));
    const Vec3 b = direction(std::acos(u(rng)), 2.0 * M_PI * u(rng));
    const float r = float(u(rng));
    const Vec3 n(0, 0, 1);
    EXPECT_NEAR(burley_factor(BurleyDiffuse{n, a, r}, b), burley_factor(BurleyDiffuse{n, b, r}, a), 1e-6f);
  }
}

TEST(BurleyDiffuse, AlbedoAtRoughnessZeroIsTheClosedForm) {
  // Roughness 0: the integral of (1 - FL / 2) cos / pi is 1 - B(2, 6) = 41 / 42 whatever wo, so the
  // albedo is (1 - FV / 2) 41 / 42: below 1 at every angle, darkest (41 / 84) at grazing.
  for (const double theta : {0.0, 0.5, 1.0, 1.3, 1.5}) {
    const Vec3 wo = direction(theta, 0.3);
    const double fv = std::pow(1.0 - std::cos(theta), 5.0);
    const double want = (1.0 - 0.5 * fv) * 41.0 / 42.0;
    EXPECT_NEAR(albedo(0.0f, wo), want, 2e-4) << "theta " << theta;
    EXPECT_LT(albedo(0.0f, wo), 1.0);
  }
}

TEST(BurleyDiffuse, RetroReflectionAddsItsClosedFormAtNormalIncidence) {
  // Seen head-on, FV = 0 and R = roughness (1 + cos_i): the retro term is roughness (1 + mu)
  // (1 - mu)^5, whose cosine-weighted integral is 2 (B(2, 6) + B(3, 6)) = 2 (1/42 + 1/168), so the
  // albedo is 41/42 + 5 roughness / 84 (above 1 at roughness 1, as Burley's diffuse is).
  for (const float r : {0.25f, 0.5f, 1.0f})
    EXPECT_NEAR(albedo(r, Vec3(0, 0, 1)), 41.0 / 42.0 + 5.0 * r / 84.0, 2e-4) << "roughness " << r;
  // Towards grazing the rough surface is brighter than the smooth one (the retro-reflection).
  const Vec3 wo = direction(1.3, 0.0);
  EXPECT_GT(albedo(1.0f, wo), albedo(0.0f, wo) + 0.05);
}

TEST(BurleyDiffuse, PrincipledHandsItToTheIntegratorOn3xOnly) {
  const std::vector<Texture> textures;
  const MaterialContext ctx{&textures};
  const Vec3 wo = glm::normalize(Vec3(0.3f, 0.0f, 1.0f));
  // Hit from below the stored normals: the Burley normal is turned to wo's side.
  const ShadingPoint below{-wo, Vec3(0, 0, 1), Vec3(0, 0, 1), Vec2(0.0f)};
  using Args = std::vector<std::pair<std::string, Params::Value>>;
  for (const double ior : {1.0, 1.5}) {
    const Principled x3 =
        Principled::from_params(Params(Args{{"burley", true}, {"layered", false}, {"roughness", 0.4}, {"ior", ior}}));
    const Scatter sc = scatter(x3, below, ctx);
    EXPECT_TRUE(sc.burley) << "ior " << ior;
    EXPECT_EQ(sc.retro.n, Vec3(0, 0, -1));
    EXPECT_EQ(sc.retro.wo, -wo);
    EXPECT_FLOAT_EQ(sc.retro.roughness, 0.4f);
    EXPECT_EQ(sc.kind, ior == 1.0 ? Scatter::Kind::Diffuse : Scatter::Kind::Glossy);
  }
  EXPECT_FALSE(scatter(Principled::from_params(Params(Args{})), below, ctx).burley);  // 4.0+: Lambert
  // A 3.x metal has no base.
  const Principled metal =
      Principled::from_params(Params(Args{{"burley", true}, {"layered", false}, {"metallic", 1.0}}));
  EXPECT_FALSE(scatter(metal, below, ctx).burley);
}
