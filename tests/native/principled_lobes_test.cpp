// The lobes a Principled BSDF hands the integrator (materials/principled.h, glossy_lobe.h), each
// as the version's Cycles builds it: 4.0+'s dielectric layer (single-scatter and Multiscatter
// GGX), 3.x's layer (separable masking), 4.0+'s F82-tint metal and the coat's lobe. For each, the
// directions sample_lobe draws are distributed as evaluate_lobe's pdf says (chi-square, as
// Mitsuba's test suite checks its BSDFs), and the single-scatter lobes are reciprocal. What is
// not reciprocal, by Cycles' own design, is checked as such: Multiscatter GGX scales the lobe by
// a factor of wo alone (1 + F_ms (1 - E(wo)) / E(wo)), so f(wo, wi) / f(wi, wo) is that factor's
// ratio. 3.x's Clearcoat is left out of the chi-square on purpose: Cycles 3.x reports a GTR1 pdf
// for its GGX-sampled directions (materials/clearcoat.h), which clearcoat_test checks.
#include "hemisphere.h"
#include "hemisphere_chi_square.h"
#include "material_fixtures.h"
#include "materials/glossy_lobe.h"
#include "materials/principled.h"
#include "statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

using namespace toyrt;
using toyrt::testing::args;
using toyrt::testing::chi_square_quantile;
using toyrt::testing::direction;
using toyrt::testing::hemisphere_chi_square;
using toyrt::testing::kContext;
using toyrt::testing::PooledChiSquare;

namespace {

struct Case {
  std::string name;
  Params params;
  bool coat_drawn = false;  // draw the coat's lobe (coat_weight 1: on half of the draws)
};

std::vector<Case> cases() {
  return {
      {"4.0+ layer, GGX", args({{"roughness", 0.4f}, {"multiscatter", false}})},
      {"4.0+ layer, Multiscatter GGX", args({{"roughness", 0.6f}})},
      {"3.x layer", args({{"roughness", 0.3f}, {"layered", false}, {"shadowing", "separable"}, {"burley", true}})},
      {"4.0+ metal", args({{"roughness", 0.5f}, {"metallic", 1.0f}, {"color", Vec3(0.9f, 0.6f, 0.3f)}})},
      {"4.0+ coat", args({{"roughness", 0.5f}, {"coat_weight", 1.0f}, {"coat_roughness", 0.3f}}), true},
  };
}

ShadingPoint hit_from(const Vec3& wo) { return ShadingPoint{wo, Vec3(0, 0, 1), Vec3(0, 0, 1), Vec2(0.0f)}; }

// The glossy lobe a Principled hit seen from wo hands over (the coat's or the layers', as asked).
GlossyLobe lobe_at(const Case& c, const Vec3& wo) {
  const Principled m = Principled::from_params(c.params);
  for (uint32_t k = 0; k < 64; ++k) {
    MaterialContext ctx = kContext;
    ctx.sample = k;
    ctx.lobe_dimension = 7;
    const Scatter sc = scatter(m, hit_from(wo), ctx);
    EXPECT_EQ(sc.kind, Scatter::Kind::Glossy) << c.name;
    const bool coat = sc.glossy.alpha == 0.3f * 0.3f && sc.glossy.ior == 1.5f;
    if (!c.coat_drawn || coat) return sc.glossy;
  }
  ADD_FAILURE() << c.name << ": the coat was never drawn";
  return {};
}

}  // namespace

TEST(PrincipledLobes, SampledDirectionsFollowTheLobesPdfChiSquare) {
  for (const Case& c : cases()) {
    for (double theta_o : {0.3, 1.2}) {
      const GlossyLobe lobe = lobe_at(c, direction(theta_o, 0.7));
      const PooledChiSquare t = hemisphere_chi_square(
          [&](const Vec2& u) {
            const BsdfSample s = sample_lobe(lobe, u);
            return s.pdf > 0.0f ? lobe.frame.to_local(s.wi) : Vec3(0.0f);
          },
          [&](const Vec3& wi) { return evaluate_lobe(lobe, lobe.frame.to_world(wi)).pdf; });
      if (t.pooled_expected < 5.0) {
        EXPECT_LT(t.pooled_count, 20.0) << c.name << ": draws where the pdf has none";
      }
      EXPECT_LT(t.chi2, chi_square_quantile(t.bins - 1, 1e-4)) << c.name << ", theta_o " << theta_o;
    }
  }
}

TEST(PrincipledLobes, SingleScatterLayersAreReciprocal) {
  // The layer's f = tint F(wo . h) D G / (4 cos_o cos_i): symmetric in wo and wi for both
  // maskings, so the lobe built at wo and evaluated at wi equals the one built at wi evaluated at
  // wo (the base beneath is not part of the lobe).
  for (const Case& c : cases()) {
    if (c.name.find("Multiscatter") != std::string::npos || c.coat_drawn) continue;
    Params params = c.params;
    params.set("multiscatter", false);
    const Case single{c.name, params};
    for (const auto& [a, b] :
         {std::pair{direction(0.3, 0.1), direction(1.0, 2.5)}, std::pair{direction(1.3, 4.0), direction(0.7, 0.9)}}) {
      const Vec3 ab = evaluate_lobe(lobe_at(single, a), b).f, ba = evaluate_lobe(lobe_at(single, b), a).f;
      ASSERT_GT(ab.x, 0.0f) << c.name;
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(ab[k], ba[k], 1e-5f * ab[k]) << c.name << " channel " << k;
    }
  }
}

TEST(PrincipledLobes, MultiscatterScalesByAFactorOfTheViewAloneAsCycles) {
  // Cycles' energy compensation multiplies the lobe by a factor of wo: the ratio f(a, b) / f(b, a)
  // is the same for every b (the factor at a over the factor at b, times 1 where the single-scatter
  // parts agree), and the compensated lobe is brighter than the single-scatter one at every angle.
  const Case multi{"multiscatter", args({{"roughness", 0.8f}})};
  const Case single{"single", args({{"roughness", 0.8f}, {"multiscatter", false}})};
  const Vec3 a = direction(1.2, 0.2);
  for (const Vec3& b : {direction(0.2, 1.0), direction(0.9, 3.0), direction(1.4, 5.0)}) {
    const float factor_a = evaluate_lobe(lobe_at(multi, a), b).f.x / evaluate_lobe(lobe_at(single, a), b).f.x;
    const float factor_b = evaluate_lobe(lobe_at(multi, b), a).f.x / evaluate_lobe(lobe_at(single, b), a).f.x;
    EXPECT_GT(factor_a, 1.0f);
    EXPECT_GT(factor_b, 1.0f);
    const float ratio = evaluate_lobe(lobe_at(multi, a), b).f.x / evaluate_lobe(lobe_at(multi, b), a).f.x;
    EXPECT_NEAR(ratio, factor_a / factor_b, 1e-4f * ratio);
    // The factor belongs to the view: the same at a whatever the light's direction.
    EXPECT_NEAR(factor_a,
                evaluate_lobe(lobe_at(multi, a), direction(0.5, 2.0)).f.x /
                    evaluate_lobe(lobe_at(single, a), direction(0.5, 2.0)).f.x,
                1e-4f * factor_a);
  }
}
