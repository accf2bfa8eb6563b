// Cycles' closures side by side (materials/closure_mixture.h) against quadratures: where every
// closure reports the density it samples, the mixture's sample weights average to the BSDF's
// albedo; with 3.x's clearcoat, which reports GTR1's pdf but draws GGX's visible normals, they
// average to Cycles' expectation, the albedo reweighted by the real mixed density over the
// reported one. The 3.x Principled with Clearcoat answers this mixture with Cycles' sample weights.
#include "materials/closure_mixture.h"
#include "hemisphere.h"
#include "material_fixtures.h"
#include "materials/clearcoat.h"
#include "materials/principled.h"
#include "sampling/ggx.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace toyrt;
using toyrt::testing::args;
using toyrt::testing::direction;
using toyrt::testing::hemisphere_integral;
using toyrt::testing::kContext;

namespace {

GlossyLobe ggx_lobe(float alpha, const Vec3& wo, const Vec3& tint) {
  GlossyLobe lobe;
  lobe.wo = wo;
  lobe.alpha = alpha;
  lobe.tint = tint;
  lobe.shadowing = GgxShadowing::Separable;
  return lobe;
}

// A diffuse part of albedo 0.5, a red GGX lobe and a second lobe, picked 0.5 / 0.3 / 0.2.
Scatter mixture(const Vec3& wo, const GlossyLobe& second) {
  Scatter sc;
  sc.kind = Scatter::Kind::Mixture;
  sc.f = Vec3(0.5f * kInvPi);
  sc.glossy = ggx_lobe(0.3f, wo, Vec3(0.9f, 0.2f, 0.1f));
  sc.second_glossy = second;
  sc.closure_pick = Vec3(0.5f, 0.3f, 0.2f);
  return sc;
}

// The mean of the sampled weights (red channel) over 40 stratified picks (which split 0.5 / 0.3 / 0.2
// exactly) x 96^2 stratified directions.
double mean_weight(const Scatter& sc) {
  constexpr int kPicks = 40, kGrid = 96;
  double sum = 0.0;
  for (int p = 0; p < kPicks; ++p)
    for (int i = 0; i < kGrid; ++i)
      for (int j = 0; j < kGrid; ++j) {
        bool diffuse = false;
        const BsdfSample s =
            mixture_sample(sc, (p + 0.5f) / kPicks, Vec2((i + 0.5f) / kGrid, (j + 0.5f) / kGrid), diffuse);
        EXPECT_TRUE(std::isfinite(s.weight.x) && std::isfinite(s.pdf));
        if (s.pdf > 0.0f) sum += s.weight.x;
      }
  return sum / (double(kPicks) * kGrid * kGrid);
}

Principled principled_3x(float coat, float metallic) {
  return Principled::from_params(args({{"color", Vec3(0.6f, 0.3f, 0.1f)},
                                       {"roughness", 0.4f},
                                       {"ior", 1.5},
                                       {"layered", false},
                                       {"burley", true},
                                       {"shadowing", std::string("separable")},
                                       {"multiscatter", false},
                                       {"metallic", metallic},
                                       {"coat_weight", coat},
                                       {"coat_roughness", 0.2f}}));
}

}  // namespace

TEST(ClosureMixture, SampleWeightsAverageToTheAlbedoWhereEveryClosureReportsItsDensity) {
  for (const double theta : {0.2, 0.9, 1.3}) {
    const Vec3 wo = direction(theta, 0.4);
    const Scatter sc = mixture(wo, ggx_lobe(0.5f, wo, Vec3(0.7f)));
    const double albedo =
        hemisphere_integral([&](const Vec3& wi) { return mixture_eval(sc, wi).f.x * wi.z; }, 2048, 1024);
    EXPECT_NEAR(mean_weight(sc), albedo, 2e-3 * albedo) << theta;
    // The mixed pdf integrates to the picks' share of each closure's mass.
    const double mass = hemisphere_integral([&](const Vec3& wi) { return mixture_eval(sc, wi).pdf; });
    const double lobes = hemisphere_integral([&](const Vec3& wi) {
      return 0.3 * evaluate_lobe(sc.glossy, wi).pdf + 0.2 * evaluate_lobe(sc.second_glossy, wi).pdf;
    });
    EXPECT_NEAR(mass, 0.5 + lobes, 1e-3) << theta;
  }
}

TEST(ClosureMixture, WithTheClearcoatTheWeightsAverageToCyclesExpectation) {
  // Cycles' estimator converges to the integral of f cos P_drawn / P: P the reported mixed pdf,
  // P_drawn the density the picks really draw with, whose clearcoat part is GGX's visible normals
  // of the clearcoat's alpha, G1(wo) D(h) / (4 cos_o) (not the GTR1 pdf it reports).
  const float alpha = 0.1f;
  for (const double theta : {0.3, 1.0}) {
    const Vec3 wo = direction(theta, 0.4);
    GlossyLobe coat = ggx_lobe(alpha, wo, Vec3(0.25f));
    coat.clearcoat = true;
    const Scatter sc = mixture(wo, coat);
    const auto drawn = [&](const Vec3& wi) {
      const Vec3 h = glm::normalize(wo + wi);
      return 0.5 * wi.z * kInvPi + 0.3 * evaluate_lobe(sc.glossy, wi).pdf +
             0.2 * ggx_g1(alpha, wo) * ggx_d(alpha, h) / (4.0 * wo.z);
    };
    const double cycles = hemisphere_integral(
        [&](const Vec3& wi) {
          const BsdfEval e = mixture_eval(sc, wi);
          return e.pdf > 0.0f ? e.f.x * wi.z * drawn(wi) / e.pdf : 0.0;
        },
        1024, 512);
    const double albedo =
        hemisphere_integral([&](const Vec3& wi) { return mixture_eval(sc, wi).f.x * wi.z; }, 1024, 512);
    EXPECT_NEAR(mean_weight(sc), cycles, 3e-3 * cycles) << theta;
    EXPECT_GT(std::abs(cycles - albedo), 1e-2 * albedo) << theta;  // the clearcoat's pdf does change the image
  }
}

TEST(ClosureMixture, The3xPrincipledWithClearcoatPicksByCyclesSampleWeights) {
  // Head-on, every Fresnel term is its F0: the diffuse closure weighs (1 - Metallic) x the base's
  // average colour, the specular F0(IOR 1.5) = 0.04 (3.x: blended towards the base colour by
  // Metallic), the clearcoat 0.25 x Clearcoat x 0.04.
  const ShadingPoint hit{Vec3(0, 0, 1), Vec3(0, 0, 1), Vec3(0, 0, 1), Vec2(0.0f)};
  for (const float metallic : {0.0f, 0.5f, 1.0f}) {
    const Scatter sc = scatter(principled_3x(0.8f, metallic), hit, kContext);
    ASSERT_EQ(sc.kind, Scatter::Kind::Mixture);
    const float diffuse = (1.0f - metallic) * (0.6f + 0.3f + 0.1f) / 3.0f;
    const float specular = (1.0f - metallic) * 0.04f + metallic * (0.6f + 0.3f + 0.1f) / 3.0f;
    const float clearcoat = 0.25f * 0.8f * 0.04f;
    const float total = diffuse + specular + clearcoat;
    EXPECT_NEAR(sc.closure_pick.x, diffuse / total, 1e-5f) << metallic;
    EXPECT_NEAR(sc.closure_pick.y, specular / total, 1e-5f) << metallic;
    EXPECT_NEAR(sc.closure_pick.z, clearcoat / total, 1e-5f) << metallic;
  }
}

TEST(ClosureMixture, The3xPrincipledWithClearcoatIsThePrincipledPlusTheClearcoatNothingAttenuated) {
  // Along any light direction the mixture's value is the bare 3.x Principled's (Burley's base and
  // the specular lobe) plus 0.25 x Clearcoat x F(IOR 1.5) x GTR1's lobe of alpha = 0.2^2.
  const float coat = 0.5f, alpha = 0.04f;
  const Vec3 wo = direction(1.0, 0.3);
  const ShadingPoint hit{wo, Vec3(0, 0, 1), Vec3(0, 0, 1), Vec2(0.0f)};
  const Scatter bare = scatter(principled_3x(0.0f, 0.0f), hit, kContext);
  const Scatter sc = scatter(principled_3x(coat, 0.0f), hit, kContext);
  for (const Vec3& wi : {direction(0.3, 2.0), direction(1.0, 3.4), direction(0.6, 0.1)}) {
    const Vec3 h = glm::normalize(wo + wi);
    const float clearcoat = 0.25f * coat * fresnel_dielectric(glm::dot(wo, h), 1.5f) * clearcoat_eval(alpha, wo, wi).f;
    const Vec3 want = evaluate_lobe(bare.glossy, wi).f + bare.f * burley_factor(bare.retro, wi) + Vec3(clearcoat);
    const Vec3 got = mixture_eval(sc, wi).f;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-5f * want[c]) << c;
    EXPECT_GT(clearcoat, 1e-3f * want.x);  // the clearcoat counts in the sum
  }
}
