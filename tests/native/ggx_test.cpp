// The GGX lobe (sampling/ggx.h) and the glossy material against known answers: D's projected
// area is 1; at normal incidence the visible-normal sampler keeps the closed-form fraction
// 1 / (1 + alpha^2) of its reflections above the horizon; the sampler's histogram matches its pdf
// (chi-square, the below-horizon mass a bin of its own); f is reciprocal; the directional albedo
// integrated numerically equals the sampler's mean weight and never exceeds 1; roughness 0
// converges to the mirror; grazing and degenerate directions give finite numbers; bad roughness
// and colours have a defined result.
#include "sampling/ggx.h"
#include "hemisphere.h"
#include "hemisphere_chi_square.h"
#include "materials/glossy.h"
#include "materials/material.h"
#include "statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

using namespace toyrt;
using toyrt::testing::chi_square_quantile;
using toyrt::testing::direction;
using toyrt::testing::hemisphere_chi_square;
using toyrt::testing::hemisphere_integral;
using toyrt::testing::pooled_chi_square;
using toyrt::testing::PooledChiSquare;

namespace {

constexpr GgxShadowing kBoth[] = {GgxShadowing::Separable, GgxShadowing::HeightCorrelated};

}  // namespace

TEST(Ggx, DistributionProjectedAreaIsOne) {
  for (float alpha : {0.1f, 0.3f, 0.7f, 1.0f}) {
    const double area =
        hemisphere_integral([&](const Vec3& m) { return double(ggx_d(alpha, m)) * m.z; }, alpha < 0.2f ? 4096 : 1024);
    EXPECT_NEAR(area, 1.0, 2e-3) << "alpha " << alpha;
  }
}

TEST(Ggx, PdfAtNormalIncidenceIntegratesToTheMassAboveTheHorizon) {
  // At normal incidence the visible normals are distributed as D cos, whose mass within
  // theta_m is tan^2 / (alpha^2 + tan^2); a reflection stays above the horizon when theta_m < 45°.
  const Vec3 wo(0.0f, 0.0f, 1.0f);
  for (float alpha : {0.3f, 0.6f, 1.0f}) {
    const double mass = hemisphere_integral(
        [&](const Vec3& wi) { return double(ggx_reflection_eval(alpha, GgxShadowing::Separable, wo, wi).pdf); }, 1024);
    EXPECT_NEAR(mass, 1.0 / (1.0 + double(alpha) * alpha), 2e-3) << "alpha " << alpha;
  }
}

TEST(Ggx, SamplerMatchesItsPdfChiSquare) {
  for (float alpha : {0.2f, 0.5f, 1.0f}) {
    for (double theta_o : {0.0, 0.8, 1.4}) {
      const Vec3 wo = direction(theta_o, 0.3);
      const PooledChiSquare t = hemisphere_chi_square(
          [&](const Vec2& u) {
            const GgxSample s = ggx_reflection_sample(alpha, GgxShadowing::Separable, wo, u);
            return s.pdf > 0.0f ? s.wi : Vec3(0.0f);
          },
          [&](const Vec3& wi) { return ggx_reflection_eval(alpha, GgxShadowing::Separable, wo, wi).pdf; });
      if (t.pooled_expected < 5.0) {
        EXPECT_LT(t.pooled_count, 20.0) << "samples where the pdf says there are none";
      }
      EXPECT_LT(t.chi2, chi_square_quantile(t.bins - 1, 1e-4)) << "alpha " << alpha << " theta_o " << theta_o;
    }
  }
}

TEST(Ggx, ReflectionIsReciprocal) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (GgxShadowing shadowing : kBoth) {
    for (int k = 0; k < 2000; ++k) {
      const float alpha = ggx_alpha(float(u(rng)));
      const Vec3 a = direction(std::acos(u(rng)), 2.0 * M_PI * u(rng));
      const Vec3 b = direction(std::acos(u(rng)), 2.0 * M_PI * u(rng));
      const float fab = ggx_reflection_eval(alpha, shadowing, a, b).f;
      const float fba = ggx_reflection_eval(alpha, shadowing, b, a).f;
      ASSERT_NEAR(fab, fba, 1e-5f * std::max(1.0f, fab)) << "alpha " << alpha;
    }
  }
}

TEST(Ggx, AlbedoIsAtMostOneAndEqualsTheSamplersMeanWeight) {
  // The white furnace of the single-scatter lobe: the directional albedo integral of f cos by
  // quadrature, against the mean of f cos / pdf over the sampler's draws (an independent
  // estimate: it never evaluates D).
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  for (GgxShadowing shadowing : kBoth) {
    for (float alpha : {0.1f, 0.3f, 0.6f, 1.0f}) {
      for (double theta_o : {0.0, 0.7, 1.2, 1.5}) {
        const Vec3 wo = direction(theta_o, 1.0);
        const double albedo = hemisphere_integral(
            [&](const Vec3& wi) { return double(ggx_reflection_eval(alpha, shadowing, wo, wi).f) * wi.z; },
            alpha < 0.2f ? 2048 : 512, alpha < 0.2f ? 1024 : 256);
        constexpr int kN = 200000;
        double mean = 0.0, mean2 = 0.0;
        for (int k = 0; k < kN; ++k) {
          const double w = ggx_reflection_sample(alpha, shadowing, wo, Vec2(uniform(rng), uniform(rng))).weight;
          ASSERT_LE(w, 1.0 + 1e-5);
          mean += w / kN;
          mean2 += w * w / kN;
        }
        const double sigma = std::sqrt(std::max(0.0, mean2 - mean * mean) / kN);
        EXPECT_LE(albedo, 1.0 + 1e-3);
        EXPECT_NEAR(albedo, mean, 4.0 * sigma + 3e-3) << "alpha " << alpha << " theta_o " << theta_o;
      }
    }
  }
}

TEST(Ggx, CorrelatedAlbedoMatchesCyclesTable) {
  // Cycles 4.0+'s single-scatter GGX albedo table (src/scene/shader.tables, table_ggx_E: Monte
  // Carlo with 2^23 samples per entry, roughness j / 31 across, cos_o i / 31 down), at a few
  // entries: the same lobe, computed independently, must give the same energy.
  struct Entry {
    int i, j;
    double e;
  };
  const Entry entries[] = {{31, 31, 0.306853}, {31, 16, 0.903873}, {31, 24, 0.592102}, {16, 31, 0.443841},
                           {8, 24, 0.727744},  {3, 31, 0.765057},  {3, 16, 0.893246}};
  for (const Entry& t : entries) {
    const double mu = t.i / 31.0, rough = t.j / 31.0;
    const float alpha = ggx_alpha(float(rough));
    const Vec3 wo(float(std::sqrt(1.0 - mu * mu)), 0.0f, float(mu));
    const double albedo = hemisphere_integral(
        [&](const Vec3& wi) {
          return double(ggx_reflection_eval(alpha, GgxShadowing::HeightCorrelated, wo, wi).f) * wi.z;
        },
        1024, 512);
    EXPECT_NEAR(albedo, t.e, 2e-3) << "roughness " << rough << " cos_o " << mu;
  }
}

TEST(Ggx, SmoothLobeReflectsAllLightAtNormalIncidence) {
  const Vec3 wo(0.0f, 0.0f, 1.0f);
  const double albedo = hemisphere_integral(
      [&](const Vec3& wi) { return double(ggx_reflection_eval(0.02f, GgxShadowing::Separable, wo, wi).f) * wi.z; },
      8192, 256);
  EXPECT_NEAR(albedo, 1.0, 2e-3);
}

TEST(Ggx, CorrelatedShadowingIsNeverDarkerThanSeparable) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < 2000; ++k) {
    const float alpha = ggx_alpha(float(u(rng)));
    const Vec3 a = direction(0.5 * M_PI * u(rng), 2.0 * M_PI * u(rng));
    const Vec3 b = direction(0.5 * M_PI * u(rng), 2.0 * M_PI * u(rng));
    EXPECT_GE(ggx_g2(alpha, GgxShadowing::HeightCorrelated, a, b) + 1e-6f,
              ggx_g2(alpha, GgxShadowing::Separable, a, b));
  }
}

TEST(Ggx, RoughnessZeroConvergesToTheMirror) {
  const float alpha = ggx_alpha(0.0f);
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  for (double theta_o : {0.0, 0.6, 1.3, 1.55}) {
    const Vec3 wo = direction(theta_o, 2.0);
    const Vec3 mirror(-wo.x, -wo.y, wo.z);
    // GGX's tail is heavy (P(tan theta_m > t) = alpha^2 / (alpha^2 + t^2) at normal incidence):
    // at alpha 1e-4, 1 sample in 2,500 strays beyond 0.01 rad.
    int strays = 0;
    constexpr int kN = 4000;
    double mean_weight = 0.0;
    for (int k = 0; k < kN; ++k) {
      const GgxSample s = ggx_reflection_sample(alpha, GgxShadowing::Separable, wo, Vec2(uniform(rng), uniform(rng)));
      if (theta_o > 1.5 && s.pdf == 0.0f) continue;  // below the horizon, rarely, at grazing
      ASSERT_GT(s.pdf, 0.0f);
      ASSERT_TRUE(std::isfinite(s.pdf));
      strays += glm::length(s.wi - mirror) > 1e-2f;
      mean_weight += s.weight / kN;
      // The lobe's own value there is finite, and its f cos / pdf is the sampler's weight.
      const GgxEval e = ggx_reflection_eval(alpha, GgxShadowing::Separable, wo, s.wi);
      ASSERT_TRUE(std::isfinite(e.f) && std::isfinite(e.pdf));
      EXPECT_NEAR(e.f * s.wi.z / e.pdf, s.weight, 1e-3f);
    }
    EXPECT_LT(strays, kN / 100) << "theta_o " << theta_o;
    EXPECT_NEAR(mean_weight, 1.0, 2e-3) << "theta_o " << theta_o;
  }
}

TEST(Ggx, GrazingAndDegenerateDirectionsAreFinite) {
  const Vec3 grazing[] = {Vec3(1.0f, 0.0f, 0.0f), Vec3(1.0f, 0.0f, 1e-8f), Vec3(0.0f, 1.0f, 1e-30f),
                          Vec3(0.6f, 0.0f, -0.8f), Vec3(0.0f, 0.0f, 1.0f)};
  for (float alpha : {kGgxMinAlpha, 0.5f, 1.0f}) {
    for (GgxShadowing shadowing : kBoth) {
      for (const Vec3& a : grazing) {
        for (const Vec3& b : grazing) {
          const GgxEval e = ggx_reflection_eval(alpha, shadowing, glm::normalize(a), glm::normalize(b));
          EXPECT_TRUE(std::isfinite(e.f) && e.f >= 0.0f && std::isfinite(e.pdf) && e.pdf >= 0.0f);
        }
        for (const Vec2 u : {Vec2(0.0f), Vec2(0.999999f), Vec2(0.5f, 0.0f), Vec2(1.0f, 1.0f)}) {
          const GgxSample s = ggx_reflection_sample(alpha, shadowing, glm::normalize(a), u);
          EXPECT_TRUE(is_finite(s.wi) && std::isfinite(s.weight) && std::isfinite(s.pdf));
          EXPECT_TRUE(s.weight >= 0.0f && s.weight <= 1.0f + 1e-5f);
        }
      }
    }
  }
  // A direction exactly opposite wo's mirror (h = 0) has no half vector: 0, not NaN.
  const GgxEval opposite =
      ggx_reflection_eval(0.5f, GgxShadowing::Separable, Vec3(0.6f, 0.0f, 0.8f), Vec3(-0.6f, 0.0f, -0.8f));
  EXPECT_EQ(opposite.f, 0.0f);
}

TEST(Ggx, RoughnessOutsideTheUnitIntervalIsClamped) {
  EXPECT_EQ(ggx_alpha(-1.0f), kGgxMinAlpha);
  EXPECT_EQ(ggx_alpha(std::nanf("")), kGgxMinAlpha);
  EXPECT_EQ(ggx_alpha(7.0f), 1.0f);
  EXPECT_FLOAT_EQ(ggx_alpha(0.5f), 0.25f);
}

TEST(GlossyMaterial, LobeIsTintedByItsColourAroundTheShadingNormal) {
  Params p;
  p.set("color", Vec3(0.9f, 0.5f, 0.1f)).set("roughness", 0.3);
  const Material m = make_material("glossy", p);
  const Glossy& g = std::get<Glossy>(m);
  const Vec3 n = glm::normalize(Vec3(0.0f, 0.2f, 1.0f));
  const ShadingPoint s{glm::normalize(Vec3(0.3f, 0.0f, 1.0f)), Vec3(0, 0, 1), n, Vec2(0.0f)};
  const Scatter sc = scatter(g, s, MaterialContext{});
  ASSERT_EQ(sc.kind, Scatter::Kind::Glossy);
  EXPECT_FLOAT_EQ(sc.glossy.alpha, 0.09f);
  EXPECT_EQ(sc.glossy.tint, Vec3(0.9f, 0.5f, 0.1f));
  EXPECT_NEAR(glm::length(sc.glossy.frame.n - n), 0.0f, 1e-6f);
  // The lobe's value along the mirror of wo about n is the tint times the GGX value there.
  const Vec3 wi = 2.0f * glm::dot(s.wo, n) * n - s.wo;
  const BsdfEval e = evaluate_lobe(sc.glossy, wi);
  const GgxEval plain = ggx_reflection_eval(0.09f, GgxShadowing::Separable, sc.glossy.wo, sc.glossy.frame.to_local(wi));
  EXPECT_NEAR(e.f.x, 0.9f * plain.f, 1e-4f * plain.f);
  EXPECT_NEAR(e.f.z, 0.1f * plain.f, 1e-4f * plain.f);
}

TEST(GlossyMaterial, WoBelowTheShadingNormalUsesTheGeometricNormal) {
  const Glossy g = Glossy::make(Vec3(1.0f), 0.5f, GgxShadowing::Separable);
  const Vec3 n = glm::normalize(Vec3(1.0f, 0.0f, 0.3f));  // tilted away from wo
  const ShadingPoint s{glm::normalize(Vec3(-1.0f, 0.0f, 0.1f)), Vec3(0, 0, 1), n, Vec2(0.0f)};
  const Scatter sc = scatter(g, s, MaterialContext{});
  EXPECT_EQ(sc.glossy.frame.n, Vec3(0, 0, 1));
  EXPECT_GT(sc.glossy.wo.z, 0.0f);
}

TEST(GlossyMaterial, BadInputIsRefusedOrClamped) {
  EXPECT_THROW(Glossy::make(Vec3(1.0f), std::nanf(""), GgxShadowing::Separable), std::invalid_argument);
  EXPECT_THROW(Glossy::make(Vec3(std::nanf(""), 0.0f, 0.0f), 0.5f, GgxShadowing::Separable), std::invalid_argument);
  EXPECT_EQ(Glossy::make(Vec3(1.0f), 3.0f, GgxShadowing::Separable).roughness, 1.0f);
  EXPECT_EQ(Glossy::make(Vec3(1.0f), -0.5f, GgxShadowing::Separable).roughness, 0.0f);
  Params p;
  p.set("shadowing", std::string("smooth"));
  EXPECT_THROW(make_material("glossy", p), std::invalid_argument);
  Params q;
  q.set("shadowing", std::string("correlated"));
  EXPECT_EQ(std::get<Glossy>(make_material("glossy", q)).shadowing, GgxShadowing::HeightCorrelated);
}
