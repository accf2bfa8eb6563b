// The Principled BSDF's Transmission (materials/principled.h) against known answers: at
// Transmission 1 it is the Glass BSDF's rough dielectric of the same roughness and conventions
// (3.x's Fresnel-weighted pair, 4.0+'s Fresnel per microfacet with Multiscatter GGX); at 0 it is
// the opaque material unchanged; in between, over the lobe-choice numbers, the glass is drawn
// with probability (1 - Metallic) Transmission, the metal with Metallic, and the base keeps its
// weight (1 - Metallic)(1 - Transmission) in expectation; bad values are refused or clamped.
#include "material_fixtures.h"
#include "materials/principled.h"
#include "materials/refraction.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

using namespace toyrt;
using toyrt::testing::kNoTextures;

namespace {

using Args = std::vector<std::pair<std::string, Params::Value>>;

Principled principled(Args args) { return Principled::from_params(Params(std::move(args))); }
ShadingPoint hit_from(const Vec3& wo) { return ShadingPoint{wo, Vec3(0, 0, 1), Vec3(0, 0, 1), Vec2(0.0f)}; }

void expect_same_lobe(const DielectricLobe& a, const DielectricLobe& b) {
  EXPECT_EQ(a.kind, b.kind);
  EXPECT_FLOAT_EQ(a.alpha, b.alpha);
  EXPECT_FLOAT_EQ(a.eta, b.eta);
  EXPECT_EQ(a.shadowing, b.shadowing);
  EXPECT_FLOAT_EQ(a.fresnel_macro, b.fresnel_macro);
  EXPECT_EQ(a.tint, b.tint);
  EXPECT_EQ(a.wo, b.wo);
}

}  // namespace

TEST(PrincipledTransmission, TransmissionOneIsTheGlassBsdf) {
  const MaterialContext ctx{&kNoTextures};
  const ShadingPoint s = hit_from(glm::normalize(Vec3(0.4f, 0.1f, 1.0f)));
  const ShadingPoint inside = hit_from(-glm::normalize(Vec3(0.4f, 0.1f, 1.0f)));
  // 4.0+ (Multiscatter GGX, height-correlated masking) and 3.x (GGX, separable, macro Fresnel).
  for (const bool new_model : {true, false}) {
    // A white base: the glass's transmission colour is then white, as the Glass BSDF's default.
    const Principled m = principled({{"transmission", 1.0},
                                     {"color", Vec3(1.0f)},
                                     {"roughness", 0.3},
                                     {"ior", new_model ? 1.5 : 1.8},
                                     {"transmission_ior", 1.5},
                                     {"layered", new_model},
                                     {"multiscatter", new_model},
                                     {"shadowing", std::string(new_model ? "correlated" : "separable")}});
    const FresnelDielectric glass = FresnelDielectric::make(
        1.5f,
        DielectricRoughness{0.3f, new_model ? GgxShadowing::HeightCorrelated : GgxShadowing::Separable,
                            MicrofacetDistribution::Ggx},
        !new_model, new_model);
    for (const ShadingPoint& at : {s, inside}) {
      const Scatter a = scatter(m, at, ctx), b = scatter(glass, at, ctx);
      ASSERT_EQ(a.kind, Scatter::Kind::Dielectric);
      ASSERT_EQ(b.kind, Scatter::Kind::Dielectric);
      expect_same_lobe(a.dielectric, b.dielectric);
      EXPECT_EQ(a.f, Vec3(0.0f));
    }
  }
}

TEST(PrincipledTransmission, TransmissionZeroLeavesTheOpaqueMaterial) {
  const ShadingPoint s = hit_from(glm::normalize(Vec3(0.4f, 0.1f, 1.0f)));
  for (const double metallic : {0.0, 0.3}) {
    const Principled with =
        principled({{"transmission", 0.0}, {"metallic", metallic}, {"color", Vec3(0.5f, 0.4f, 0.3f)}});
    const Principled without = principled({{"metallic", metallic}, {"color", Vec3(0.5f, 0.4f, 0.3f)}});
    for (uint32_t i = 0; i < 64; ++i) {
      const MaterialContext ctx{&kNoTextures, false, 0, i, 1, 0, 7};
      const Scatter a = scatter(with, s, ctx), b = scatter(without, s, ctx);
      EXPECT_EQ(a.kind, b.kind);
      EXPECT_EQ(a.f, b.f);
      EXPECT_EQ(a.glossy.f0, b.glossy.f0);
      EXPECT_EQ(a.glossy.fresnel, b.glossy.fresnel);
    }
  }
}

TEST(PrincipledTransmission, PartialTransmissionDrawsEachPartWithItsWeight) {
  // Over the lobe-choice numbers (Sobol-Owen, one per sample), the glass is drawn with
  // probability (1 - Metallic) Transmission and the metal with Metallic; the base's f, present
  // whenever the glass is not drawn, averages to its opaque value times (1 - Transmission).
  const ShadingPoint s = hit_from(glm::normalize(Vec3(0.4f, 0.1f, 1.0f)));
  const Vec3 color(0.5f, 0.4f, 0.3f);
  constexpr int kN = 1 << 14;
  for (const bool new_model : {true, false})
    for (const double metallic : {0.0, 0.4})
      for (const double t : {0.25, 0.7}) {
        const Args common{{"roughness", 0.4}, {"metallic", metallic}, {"color", color}, {"layered", new_model}};
        Args with_glass = common;
        with_glass.push_back({"transmission", t});
        const Principled m = principled(with_glass), opaque = principled(common);
        int glass = 0, metal = 0;
        Vec3 f_sum(0.0f), f_opaque(0.0f);
        for (uint32_t i = 0; i < uint32_t(kN); ++i) {
          const MaterialContext ctx{&kNoTextures, false, 3, i, 1, 0, 7};
          const Scatter sc = scatter(m, s, ctx);
          glass += sc.kind == Scatter::Kind::Dielectric;
          // The metal lobe's Fresnel is the base colour's (3.x: a blend towards it; 4.0+: F82).
          metal += new_model && sc.kind == Scatter::Kind::Glossy && sc.glossy.fresnel == LobeFresnel::F82Tint;
          f_sum += sc.f;
          f_opaque += scatter(opaque, s, ctx).f;
        }
        const double share = (1.0 - metallic) * t;
        EXPECT_NEAR(double(glass) / kN, share, 2e-3) << "metallic " << metallic << " t " << t;
        if (new_model) {
          EXPECT_NEAR(double(metal) / kN, metallic, 2e-3) << "metallic " << metallic << " t " << t;
        }
        const Vec3 want = float(1.0 - t) * f_opaque / float(kN);
        const Vec3 got = f_sum / float(kN);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 2e-3f * want[c] + 1e-7f) << "channel " << c;
      }
}

TEST(PrincipledTransmission, BadValuesAreRefusedOrClamped) {
  EXPECT_THROW(principled({{"transmission", std::nan("")}}), std::invalid_argument);
  EXPECT_THROW(principled({{"transmission", 0.5}, {"transmission_ior", 0.0}}), std::invalid_argument);
  EXPECT_FLOAT_EQ(principled({{"transmission", 2.0}}).transmission, 1.0f);
  EXPECT_FLOAT_EQ(principled({{"transmission", -1.0}}).transmission, 0.0f);
}
