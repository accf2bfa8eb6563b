// Blender 3.x's Principled Clearcoat (materials/clearcoat.h, materials/principled.cpp) against
// closed forms and invariants: GTR1's normalisation, the sampler and the evaluation reporting the
// same (Cycles') pdf and a weight of f cos / pdf, no NaN at roughness 0 or grazing. How the
// Principled combines it with its other closures: tests/native/closure_mixture_test.cpp.
#include "materials/clearcoat.h"
#include "hemisphere.h"
#include "material_fixtures.h"
#include "materials/fresnel.h"
#include "materials/glossy_lobe.h"
#include "materials/principled.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace toyrt;
using toyrt::testing::args;
using toyrt::testing::direction;
using toyrt::testing::kContext;

namespace {

// A Blender 3.x Principled as the add-on sends it, with Clearcoat `coat`.
Principled principled_3x(float coat, float coat_roughness) {
  return Principled::from_params(args({{"color", Vec3(0.6f, 0.3f, 0.1f)},
                                       {"roughness", 0.4f},
                                       {"ior", 1.5},
                                       {"layered", false},
                                       {"burley", true},
                                       {"shadowing", std::string("separable")},
                                       {"multiscatter", false},
                                       {"coat_weight", coat},
                                       {"coat_roughness", coat_roughness}}));
}

ShadingPoint hit_from(const Vec3& wo) { return ShadingPoint{wo, Vec3(0, 0, 1), Vec3(0, 0, 1), Vec2(0.0f)}; }

}  // namespace

TEST(Clearcoat, Gtr1IntegratesToOneOverTheProjectedHemisphere) {
  // int D(h) cos dh = 2 pi int_0^1 D(sqrt(x)) dx / 2 over x = cos^2: midpoint rule, 2^20 steps.
  for (const float alpha : {0.05f, 0.2f, 0.5f, 0.9f, 1.0f}) {
    constexpr int kN = 1 << 20;
    double sum = 0.0;
    for (int i = 0; i < kN; ++i) {
      const double x = (i + 0.5) / kN;
      sum += gtr1_d(alpha, Vec3(float(std::sqrt(1.0 - x)), 0.0f, float(std::sqrt(x))));
    }
    EXPECT_NEAR(sum / kN * kPi, 1.0, 1e-3) << alpha;
  }
}

TEST(Clearcoat, SamplerAndEvaluationReportCyclesPdfAndWeighFCosOverIt) {
  for (const float alpha : {1e-4f, 0.01f, 0.09f, 0.49f, 1.0f})
    for (const double theta : {0.0, 0.7, 1.4, 1.5707}) {
      const Vec3 wo = direction(theta, 0.3);
      for (int k = 0; k < 64; ++k) {
        const Vec2 u((k % 8 + 0.5f) / 8.0f, (k / 8 + 0.5f) / 8.0f);
        const GgxSample s = clearcoat_sample(alpha, wo, u);
        ASSERT_TRUE(std::isfinite(s.weight) && std::isfinite(s.pdf));
        if (!(s.weight > 0.0f)) continue;
        const GgxEval e = clearcoat_eval(alpha, wo, s.wi);
        // The half vector rebuilt from wi rounds differently from the drawn normal: on the
        // sharpest lobe (alpha 1e-4: D ~ 1e7) that moves D by a few 1e-4.
        // At the horizon (wo.z 1e-4) the rebuilt half vector of a near-mirror lobe is off by more
        // than the lobe's width: there only finiteness is checked.
        if (alpha < 0.02f && theta > 1.5) continue;
        const float tolerance = alpha < 1e-3f ? 2e-3f : 2e-4f;
        EXPECT_NEAR(e.pdf, s.pdf, tolerance * s.pdf) << alpha << " " << theta << " " << k;
        EXPECT_NEAR(s.weight, e.f * s.wi.z / e.pdf, tolerance * s.weight) << alpha << " " << theta << " " << k;
        EXPECT_LE(s.weight, 1.0f);  // G1 of the fixed masking
      }
    }
}

TEST(Clearcoat, WithoutClearcoatThe3xPrincipledIsUnchangedAndAMirrorCoatStaysFinite) {
  const ShadingPoint hit = hit_from(direction(1.2, 0.0));
  const Scatter none = scatter(principled_3x(0.0f, 0.03f), hit, kContext);
  const Scatter plain = scatter(Principled::from_params(args({{"color", Vec3(0.6f, 0.3f, 0.1f)},
                                                              {"roughness", 0.4f},
                                                              {"ior", 1.5},
                                                              {"layered", false},
                                                              {"burley", true},
                                                              {"shadowing", std::string("separable")},
                                                              {"multiscatter", false}})),
                                hit, kContext);
  EXPECT_EQ(none.f, plain.f);
  EXPECT_EQ(none.glossy.tint, plain.glossy.tint);
  EXPECT_EQ(none.glossy.alpha, plain.glossy.alpha);
  // Clearcoat Roughness 0 at grazing: finite values wherever the lobe is evaluated or sampled.
  for (const double theta : {0.0, 1.3, 1.5707}) {
    const Vec3 wo = direction(theta, 0.0);
    for (int k = 0; k < 16; ++k) {
      const GgxSample s = clearcoat_sample(kGgxMinAlpha, wo, Vec2((k + 0.5f) / 16.0f, 0.37f));
      EXPECT_TRUE(std::isfinite(s.weight) && std::isfinite(s.pdf));
      const GgxEval e = clearcoat_eval(kGgxMinAlpha, wo, direction(0.1 * k, 1.0));
      EXPECT_TRUE(std::isfinite(e.f) && std::isfinite(e.pdf));
    }
  }
}
