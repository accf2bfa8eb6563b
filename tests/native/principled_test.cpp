// The Principled BSDF (materials/principled.h) and Multiscatter GGX (materials/multiscatter.h)
// against known answers: a white Principled surface in a white furnace reflects all the light it
// gets (the layering's whole point), at normal incidence the layer reflects F0 and the base the
// rest; a white multiscatter lobe reflects everything; Specular IOR Level 0 or IOR 1 is plain
// Lambert; the lobe's sampled weights equal f cos / pdf with its Fresnel term; bad parameters have
// a defined answer; 4.0+'s coat leaves below it what Cycles' estimate of its albedo leaves, its
// lobe is energy-compensated, and a white coated surface returns about all light, never more;
// the uncoated layer's pick share is Cycles' sample weights' and the weight of a continuation
// under that pick averages to the closures' mixed-pdf estimator (render/closure_pick.h).
#include "materials/principled.h"
#include "hemisphere.h"
#include "material_fixtures.h"
#include "materials/coat.h"
#include "materials/fresnel.h"
#include "materials/glossy.h"
#include "materials/material.h"
#include "materials/multiscatter.h"
#include "render/closure_pick.h"
#include "sampling/ggx_albedo.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

using namespace toyrt;
using toyrt::testing::args;
using toyrt::testing::direction;
using toyrt::testing::hemisphere_integral;
using toyrt::testing::kContext;

namespace {

Principled principled(const Params& params) { return Principled::from_params(params); }

// A hit on the plane z = 0 seen from wo.
ShadingPoint hit_from(const Vec3& wo) { return ShadingPoint{wo, Vec3(0, 0, 1), Vec3(0, 0, 1), Vec2(0.0f)}; }

// What the surface returns of uniform white light from every direction: the lobe's albedo (the
// mean of f cos / pdf over its samples, 256^2 strata: exact in the limit however sharp the lobe),
// plus the diffuse part's albedo (f pi).
Vec3 furnace(const Scatter& sc) {
  const Vec3 base = sc.f * kPi;
  if (sc.kind != Scatter::Kind::Glossy) return base;
  constexpr int kN = 256;
  Vec3 sum(0.0f);
  for (int i = 0; i < kN; ++i)
    for (int j = 0; j < kN; ++j) sum += sample_lobe(sc.glossy, Vec2((i + 0.5f) / kN, (j + 0.5f) / kN)).weight;
  return base + sum / float(kN * kN);
}

// The same albedo by quadrature of the lobe's value: checks evaluate_lobe where the lobe is wide.
float lobe_integral(const GlossyLobe& lobe) {
  return float(
      hemisphere_integral([&](const Vec3& wi) { return double(evaluate_lobe(lobe, wi).f.x) * wi.z; }, 1024, 256));
}

}  // namespace

TEST(Principled, WhiteSurfaceInAWhiteFurnaceReflectsAllLight) {
  // Energy layering: the base gets what the layer does not reflect, so a white base and an untinted
  // layer return 1 at every angle and roughness (up to the albedo tables' interpolation).
  for (const bool ms : {true, false})
    for (const float rough : {0.1f, 0.3f, 0.5f, 0.8f, 1.0f})
      for (const double theta : {0.0, 0.6, 1.2, 1.45}) {
        const Principled m = principled(args({{"color", Vec3(1.0f)}, {"roughness", rough}, {"multiscatter", ms}}));
        const Vec3 r = furnace(scatter(m, hit_from(direction(theta, 0.4)), kContext));
        // Plain GGX loses the inter-reflections, a few per cent at roughness 1; the base then is
        // not told (Cycles' estimate assumes they are there), so it stays below 1.
        const double lo = ms ? 0.985 : 0.93;
        EXPECT_LE(r.x, 1.0f + 0.01f) << rough << " " << theta << " " << ms;
        EXPECT_GE(r.x, lo) << rough << " " << theta << " " << ms;
      }
}

TEST(Principled, NormalIncidenceOnASmoothLayerReflectsF0AndTheBaseTheRest) {
  const Principled m =
      principled(args({{"color", Vec3(0.5f)}, {"roughness", 0.0f}, {"ior", 1.5}, {"multiscatter", false}}));
  const Scatter sc = scatter(m, hit_from(Vec3(0, 0, 1)), kContext);
  ASSERT_EQ(sc.kind, Scatter::Kind::Glossy);
  EXPECT_NEAR(sc.f.x * kPi, 0.5f * (1.0f - 0.04f), 2e-3f);
  // The sharp lobe reflects F0 = 0.04 at normal incidence: f cos / pdf of its samples is F.
  const BsdfSample s = sample_lobe(sc.glossy, Vec2(0.3f, 0.7f));
  EXPECT_NEAR(s.weight.x, 0.04f, 1e-3f);
  // Specular IOR Level 1 doubles F0; Specular Tint scales it per channel.
  const Principled tinted = principled(args({{"roughness", 0.0f},
                                             {"ior", 1.5},
                                             {"specular_ior_level", 1.0},
                                             {"specular_tint", Vec3(1.0f, 0.5f, 0.0f)},
                                             {"multiscatter", false}}));
  const BsdfSample t = sample_lobe(scatter(tinted, hit_from(Vec3(0, 0, 1)), kContext).glossy, Vec2(0.3f, 0.7f));
  EXPECT_NEAR(t.weight.x, 0.08f, 1e-3f);
  EXPECT_NEAR(t.weight.y, 0.04f, 1e-3f);
  EXPECT_NEAR(t.weight.z, 0.0f, 1e-6f);
}

TEST(Principled, NoSpecularLayerIsPlainLambert) {
  for (const Params& p : std::vector<Params>{args({{"color", Vec3(0.3f, 0.6f, 0.9f)}, {"specular_ior_level", 0.0}}),
                                             args({{"color", Vec3(0.3f, 0.6f, 0.9f)}, {"ior", 1.0}})}) {
    const Scatter sc = scatter(principled(p), hit_from(direction(0.7, 0.1)), kContext);
    EXPECT_EQ(sc.kind, Scatter::Kind::Diffuse);
    EXPECT_EQ(sc.f, Vec3(0.3f, 0.6f, 0.9f) * kInvPi);
  }
}

TEST(Principled, SampledWeightIsFCosOverPdf) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int k = 0; k < 2000; ++k) {
    const Principled m = principled(args({{"roughness", u(rng)},
                                          {"ior", 1.0 + 2.0 * u(rng)},
                                          {"specular_tint", Vec3(u(rng), u(rng), u(rng))},
                                          {"multiscatter", k % 2 == 0},
                                          {"coat_weight", k % 3 == 0 ? u(rng) : 0.0f},
                                          {"coat_roughness", u(rng)}}));
    MaterialContext ctx = kContext;  // with a coat, either lobe is drawn
    ctx.sample = uint32_t(k);
    ctx.lobe_dimension = 7;
    const Scatter sc = scatter(m, hit_from(direction(1.5 * u(rng), 6.0 * u(rng))), ctx);
    const BsdfSample s = sample_lobe(sc.glossy, Vec2(u(rng), u(rng)));
    if (!(s.pdf > 0.0f)) continue;
    const BsdfEval e = evaluate_lobe(sc.glossy, s.wi);
    EXPECT_NEAR(e.pdf, s.pdf, 1e-3f * s.pdf);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(s.weight[c], e.f[c] * s.wi.z / e.pdf, 1e-3f * (1.0f + s.weight[c]));
  }
}

TEST(Principled, LayerIsBrighterAtGrazingAndTheBaseDarker) {
  const Principled m = principled(args({{"color", Vec3(1.0f)}, {"roughness", 0.3f}}));
  const Scatter head_on = scatter(m, hit_from(direction(0.0, 0.0)), kContext);
  const Scatter grazing = scatter(m, hit_from(direction(1.4, 0.0)), kContext);
  EXPECT_GT(head_on.f.x, grazing.f.x);
  EXPECT_LT(furnace(head_on).x - head_on.f.x * kPi, furnace(grazing).x - grazing.f.x * kPi);
  // The value the integrator uses for light samples integrates to the same albedo.
  EXPECT_NEAR(lobe_integral(grazing.glossy), furnace(grazing).x - grazing.f.x * kPi, 2e-3f);
}

TEST(Principled, BadParametersAreRefusedOrClamped) {
  EXPECT_THROW(principled(args({{"ior", 0.0}})), std::invalid_argument);
  EXPECT_THROW(principled(args({{"roughness", NAN}})), std::invalid_argument);
  EXPECT_THROW(principled(args({{"specular_ior_level", -1.0}})), std::invalid_argument);
  EXPECT_THROW(principled(args({{"specular_tint", Vec3(NAN)}})), std::invalid_argument);
  EXPECT_EQ(principled(args({{"roughness", 7.0f}})).roughness, 1.0f);
  // A huge level is a white mirror-like layer over nothing; an index below 1 (light leaving a
  // denser medium: total internal reflection) is finite. Cycles' layering estimate reads the
  // table of 1 / ior there, which misses the internal reflection, so that sum may exceed 1 as
  // it does in Cycles.
  const Vec3 level =
      furnace(scatter(principled(args({{"specular_ior_level", 1e6}})), hit_from(direction(1.0, 0.0)), kContext));
  EXPECT_NEAR(level.x, 1.0f, 0.01f);
  EXPECT_TRUE(is_finite(furnace(scatter(principled(args({{"ior", 0.5}})), hit_from(direction(1.0, 0.0)), kContext))));
  EXPECT_EQ(std::string(std::visit([](const auto& m) { return m.kType; }, make_material("principled", args({})))),
            "principled");
}

TEST(MultiscatterGgx, WhiteLobeReflectsAllLight) {
  for (const float rough : {0.2f, 0.5f, 0.8f, 1.0f})
    for (const double theta : {0.0, 0.7, 1.3}) {
      const Glossy g = Glossy::make(Vec3(1.0f), rough, GgxShadowing::HeightCorrelated, true);
      const Vec3 r = furnace(scatter(g, hit_from(direction(theta, 0.0)), kContext));
      EXPECT_NEAR(r.x, 1.0f, 5e-3f) << rough << " " << theta;
    }
}

TEST(MultiscatterGgx, ColouredLobeKeepsLessOfEachBounce) {
  // With colour c < 1 each extra bounce is tinted again, so the compensation adds less than
  // (1 - E) c: the albedo lies between the single-scatter c E and c.
  const float rough = 0.9f, theta = 0.5f;
  const Glossy ms = Glossy::make(Vec3(0.5f), rough, GgxShadowing::HeightCorrelated, true);
  const Glossy ss = Glossy::make(Vec3(0.5f), rough, GgxShadowing::HeightCorrelated, false);
  const float a_ms = furnace(scatter(ms, hit_from(direction(theta, 0.0)), kContext)).x;
  const float a_ss = furnace(scatter(ss, hit_from(direction(theta, 0.0)), kContext)).x;
  EXPECT_GT(a_ms, a_ss);
  EXPECT_LT(a_ms, a_ss + 0.5f * (1.0f - 2.0f * a_ss));  // below c E + c (1 - E) with c = 0.5
}

TEST(Principled, Blender3xSumKeepsTheWholeBaseUnderTheSameLayer) {
  const Params p3 = args(
      {{"color", Vec3(0.6f)}, {"layered", false}, {"shadowing", std::string("separable")}, {"multiscatter", false}});
  const Params p4 = args({{"color", Vec3(0.6f)}, {"shadowing", std::string("separable")}, {"multiscatter", false}});
  const ShadingPoint hit = hit_from(direction(0.9, 0.2));
  const Scatter s3 = scatter(principled(p3), hit, kContext), s4 = scatter(principled(p4), hit, kContext);
  EXPECT_EQ(s3.f, Vec3(0.6f) * kInvPi);
  EXPECT_LT(s4.f.x, s3.f.x);
  const Vec3 wi = direction(0.5, 3.0);
  EXPECT_EQ(evaluate_lobe(s3.glossy, wi).f, evaluate_lobe(s4.glossy, wi).f);
  EXPECT_EQ(s3.glossy.shadowing, GgxShadowing::Separable);
}

// Cycles' sample weights: the layer's mix(F0, 1, s) E (1 + F_ms (1 - E) / E) (colourless), the
// base's average colour times the share it keeps, 1 minus the layer's.
TEST(Principled, GlossyPickIsTheLayersShareOfCyclesSampleWeights) {
  const Vec3 color(0.7f, 0.08f, 0.05f);
  const Principled m = principled(args({{"color", color}, {"roughness", 0.5}, {"ior", 1.5}}));
  for (const double theta : {0.2, 0.9, 1.4}) {
    const ShadingPoint hit = hit_from(direction(theta, 0.3));
    const float mu = float(std::cos(theta));
    const float s = ggx_fresnel_blend(0.5f, mu, 1.5f);
    const float f_ms = multiscatter_scale(0.5f, mu, m.fss).x;
    const float layer = (0.04f + 0.96f * s) * ggx_albedo(0.5f, mu) * f_ms;
    const float base = (color.x + color.y + color.z) / 3.0f * (1.0f - layer);
    const Scatter sc = scatter(m, hit, kContext);
    EXPECT_NEAR(sc.glossy_pick, layer / (layer + base), 1e-4f) << theta;
  }
  // 3.x (Cycles 3.x's weights): the layer's F0 blended to white by the IOR's normalised Fresnel
  // curve at the view, against the base's average colour, whole (3.x adds the layer to it).
  const Principled m3 = principled(args({{"color", color},
                                         {"roughness", 0.5},
                                         {"ior", 1.5},
                                         {"layered", false},
                                         {"burley", true},
                                         {"multiscatter", false},
                                         {"shadowing", std::string("separable")}}));
  for (const double theta : {0.2, 0.9, 1.4}) {
    const float curve = (fresnel_dielectric(float(std::cos(theta)), 1.5f) - 0.04f) / 0.96f;
    const float layer = 0.04f + 0.96f * curve;
    const float base = (color.x + color.y + color.z) / 3.0f;
    EXPECT_NEAR(scatter(m3, hit_from(direction(theta, 0.3)), kContext).glossy_pick, layer / (layer + base), 1e-4f)
        << theta;
  }
  // Only there: a coat, a metal (4.0+) or glass beside the layer leave the lobe its own weight.
  const ShadingPoint hit = hit_from(direction(0.9, 0.3));
  for (const Params& p : std::vector<Params>{
           args({{"color", color}, {"layered", false}, {"multiscatter", false}, {"coat_weight", 0.5}}),
           args({{"color", color}, {"coat_weight", 0.5}}),
           args({{"color", color}, {"metallic", 0.5}}),
           args({{"color", color}, {"transmission", 0.5}}),
       })
    EXPECT_EQ(scatter(principled(p), hit, kContext).glossy_pick, 0.0f);
}

// Averaged over the lobe's own samples, the continuation's weight under Cycles' pick is the
// quadrature of (f_g + f_d) cos w p_g / (w p_g + (1 - w) cos / pi): the glossy picks' share of
// the whole BSDF; a lobe without a diffuse part (w = 1) keeps its own weight.
TEST(Principled, PickedContinuationAveragesToTheGlossyPicksShareOfTheWholeBsdf) {
  const Principled m = principled(args({{"color", Vec3(0.7f, 0.08f, 0.05f)}, {"roughness", 0.5}, {"ior", 1.5}}));
  const Scatter sc = scatter(m, hit_from(direction(0.9, 0.3)), kContext);
  ASSERT_GT(sc.glossy_pick, 0.0f);
  const float w = sc.glossy_pick;
  constexpr int kN = 512;
  double sampled = 0.0;
  for (int i = 0; i < kN; ++i)
    for (int j = 0; j < kN; ++j) {
      const BsdfSample b = sample_lobe(sc.glossy, Vec2((i + 0.5f) / kN, (j + 0.5f) / kN));
      if (!(b.pdf > 0.0f)) continue;
      const Vec3 v = closure_pick_weight(b.weight, b.pdf, sc.f, b.wi.z, w);
      sampled += v.x;
      const Vec3 alone = closure_pick_weight(b.weight, b.pdf, Vec3(0.0f), b.wi.z, 1.0f);
      EXPECT_NEAR(alone.x, b.weight.x, 1e-5f * b.weight.x);
    }
  sampled /= double(kN) * kN;
  const double quadrature = hemisphere_integral(
      [&](const Vec3& wi) {
        const BsdfEval e = evaluate_lobe(sc.glossy, wi);
        const double mixed = w * e.pdf + (1.0 - w) * wi.z * kInvPi;
        return mixed > 0.0 ? (e.f.x + sc.f.x) * wi.z * w * e.pdf / mixed : 0.0;
      },
      1024, 256);
  EXPECT_NEAR(sampled, quadrature, 2e-3 * quadrature);
  // More than the lobe alone (the base's share), less than the whole BSDF's albedo.
  EXPECT_GT(sampled, furnace(Scatter::glossy_lobe(sc.glossy)).x);
  EXPECT_LT(sampled, furnace(sc).x);
}

TEST(PrincipledMetal, F82TintScalesSchlickAt82DegreesAndAveragesInClosedForm) {
  const Vec3 f0(0.9f, 0.6f, 0.3f), tint(1.0f, 0.7f, 0.2f);
  const Vec3 b = f82_tint_b(f0, tint);
  const float c = 1.0f / 7.0f, m5 = std::pow(1.0f - c, 5.0f);
  const Vec3 schlick = glm::mix(f0, Vec3(1.0f), m5);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(fresnel_f82(c, f0, b)[i], schlick[i] * tint[i], 1e-5f);
  EXPECT_EQ(fresnel_f82(1.0f, f0, b), f0);
  EXPECT_EQ(f82_tint_b(f0, Vec3(1.0f)), Vec3(0.0f));
  // The closed-form average against a fine midpoint rule (F stays inside [0, 1] here).
  constexpr int kN = 1 << 16;
  Vec3 sum(0.0f);
  for (int k = 0; k < kN; ++k) {
    const float mu = (k + 0.5f) / kN;
    sum += 2.0f * mu * fresnel_f82(mu, f0, b) / float(kN);
  }
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(f82_average(f0, b)[i], sum[i], 1e-4f);
}

TEST(PrincipledMetal, SmoothMetalReflectsItsBaseColourHeadOnAndWhiteLightFully) {
  for (const bool layered : {true, false}) {
    const Principled m = principled(args({{"color", Vec3(0.9f, 0.5f, 0.2f)},
                                          {"metallic", 1.0},
                                          {"roughness", 0.0f},
                                          {"layered", layered},
                                          {"multiscatter", false}}));
    const Scatter sc = scatter(m, hit_from(Vec3(0, 0, 1)), kContext);
    EXPECT_EQ(sc.f, Vec3(0.0f));  // no base under a metal
    const Vec3 w = sample_lobe(sc.glossy, Vec2(0.4f, 0.1f)).weight;
    EXPECT_NEAR(w.x, 0.9f, 1e-3f);
    EXPECT_NEAR(w.z, 0.2f, 1e-3f);
  }
  // A white metal with the multiscatter compensation returns all light at every roughness.
  for (const float rough : {0.3f, 0.7f, 1.0f}) {
    const Principled white = principled(args({{"color", Vec3(1.0f)}, {"metallic", 1.0}, {"roughness", rough}}));
    EXPECT_NEAR(furnace(scatter(white, hit_from(direction(0.8, 0.0)), kContext)).x, 1.0f, 5e-3f) << rough;
  }
}

TEST(PrincipledMetal, PartlyMetallicIsTheMixOfMetalAndDielectricInExpectation) {
  // 4.0+: one of the two lobes per hit, drawn with its weight; the mean over the draws is
  // metallic x metal + (1 - metallic) x dielectric, and the base is (1 - metallic) of the
  // dielectric's in every draw.
  const Params common = args({{"color", Vec3(0.8f, 0.4f, 0.2f)}, {"roughness", 0.4f}, {"ior", 1.5}});
  auto with = [&](double metallic) {
    Params p = common;
    p.set("metallic", metallic);
    return principled(p);
  };
  const ShadingPoint hit = hit_from(direction(0.6, 0.3));
  const Scatter metal = scatter(with(1.0), hit, kContext), dielectric = scatter(with(0.0), hit, kContext);
  const Principled mixed = with(0.3);
  const Vec3 expected = 0.3f * furnace(metal) + 0.7f * furnace(dielectric);
  Vec3 mean(0.0f);
  constexpr int kDraws = 64;
  int metal_draws = 0;
  for (uint32_t k = 0; k < kDraws; ++k) {
    MaterialContext ctx = kContext;
    ctx.sample = k;
    ctx.lobe_dimension = 7;
    const Scatter sc = scatter(mixed, hit, ctx);
    EXPECT_EQ(sc.f, 0.7f * dielectric.f);
    metal_draws += sc.glossy.fresnel == LobeFresnel::F82Tint;
    mean += furnace(sc) / float(kDraws);
  }
  EXPECT_NEAR(metal_draws, 0.3 * kDraws, 2.0);  // stratified Sobol draws
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean[c], expected[c], 0.02f) << c;
  // 3.x: one lobe, F0 blended to the base colour; the base weighted 1 - metallic.
  Params p3 = common;
  p3.set("metallic", 0.3).set("layered", false).set("multiscatter", false);
  const Scatter sc3 = scatter(principled(p3), hit_from(Vec3(0, 0, 1)), kContext);
  const Vec3 w = sample_lobe(sc3.glossy, Vec2(0.5f, 0.5f)).weight;
  EXPECT_NEAR(sc3.f.x * kPi, 0.7f * 0.8f, 1e-5f);
  EXPECT_EQ(sc3.glossy.f0, glm::mix(Vec3(0.04f), Vec3(0.8f, 0.4f, 0.2f), 0.3f));
  EXPECT_GT(w.x, w.z);
}

// ---- 4.0+'s Coat (materials/coat.h) ----------------------------------------------------------

namespace {

// The mean over `draws` stratified lobe choices of what the coated surface returns of uniform
// white light (the coat is drawn on coat / 2 of them with its weight divided by that).
Vec3 coated_furnace(const Principled& m, const ShadingPoint& hit, int draws) {
  Vec3 mean(0.0f);
  for (int k = 0; k < draws; ++k) {
    MaterialContext ctx = kContext;
    ctx.sample = uint32_t(k);
    ctx.lobe_dimension = 7;
    mean += furnace(scatter(m, hit, ctx)) / float(draws);
  }
  return mean;
}

Principled coated(float coat, float coat_roughness, const Vec3& color = Vec3(1.0f)) {
  return principled(args({{"color", color},
                          {"roughness", 0.5f},
                          {"coat_weight", coat},
                          {"coat_roughness", coat_roughness},
                          {"coat_ior", 1.5}}));
}

}  // namespace

TEST(PrincipledCoat, BaseKeepsWhatCyclesEstimateOfTheCoatLeaves) {
  // The diffuse part under a coat, on either draw, is the bare one times 1 - weight x the coat
  // closure's estimated albedo: E (1 + F_ms (1 - E) / E) mix(F0, 1, s) from the tables, Fss the
  // IOR's average Fresnel. Not the Fresnel term at wo: at grazing angles a rough coat reflects
  // less than that, and Cycles leaves the difference to the layers below.
  const float f0 = 0.04f, fss = fresnel_dielectric_average(1.5f);
  for (const float coat_rough : {0.05f, 0.3f, 0.7f})
    for (const double theta : {0.0, 0.9, 1.4}) {
      const ShadingPoint hit = hit_from(direction(theta, 0.2));
      const float mu = float(std::cos(theta));
      const float e = ggx_albedo(coat_rough, mu), e_avg = ggx_average_albedo(coat_rough);
      const float f_ms = fss * e_avg / (1.0f - fss * (1.0f - e_avg));
      const float estimate = (e + f_ms * (1.0f - e)) * (f0 + (1.0f - f0) * ggx_fresnel_blend(coat_rough, mu, 1.5f));
      const Scatter bare = scatter(coated(0.0f, coat_rough, Vec3(0.6f)), hit, kContext);
      for (const float weight : {0.5f, 1.0f}) {
        const Scatter sc = scatter(coated(weight, coat_rough, Vec3(0.6f)), hit, kContext);
        EXPECT_NEAR(sc.f.x, bare.f.x * (1.0f - weight * estimate), 1e-5f * bare.f.x) << coat_rough << " " << theta;
      }
      if (theta > 1.3 && coat_rough > 0.2f) {
        EXPECT_LT(estimate, fresnel_dielectric(mu, 1.5f));
      }
    }
}

TEST(PrincipledCoat, CoatLobeCarriesItsEnergyCompensation) {
  // The coat's lobe is Cycles' energy-compensated GGX whatever the distribution: drawn with
  // probability weight / 2, its tint is 2 (1 + F_ms (1 - E) / E).
  const float rough = 0.6f, mu = float(std::cos(1.0));
  const float scale = multiscatter_scale(rough, mu, Vec3(fresnel_dielectric_average(1.5f))).x;
  EXPECT_GT(scale, 1.0f);
  for (const bool ms : {true, false}) {
    Params p = args({{"coat_weight", 1.0}, {"coat_roughness", rough}, {"multiscatter", ms}});
    const Principled m = principled(p);
    MaterialContext ctx = kContext;
    ctx.lobe_dimension = 7;
    bool seen = false;
    for (uint32_t k = 0; k < 8 && !seen; ++k) {
      ctx.sample = k;
      const Scatter sc = scatter(m, hit_from(direction(1.0, 0.0)), ctx);
      if (sc.glossy.alpha != rough * rough) continue;  // the specular layer was drawn
      seen = true;
      EXPECT_NEAR(sc.glossy.tint.x, 2.0f * scale, 1e-5f);
    }
    EXPECT_TRUE(seen);
  }
}

TEST(PrincipledCoat, WhiteCoatedSurfaceInAWhiteFurnaceReflectsAboutAllLight) {
  // A white base under an untinted coat: the coat reflects about what Cycles' estimate takes off
  // below, so the sum stays near 1 and never above it, at every angle and coat roughness (the
  // estimate is the table's, not the lobe's own albedo: within 2 %). Scaling the base by the
  // plain Fresnel term at wo (and no compensation) instead returned 0.39-0.97 at 75-86 degrees
  // for every coat roughness here.
  for (const float coat_rough : {0.05f, 0.3f, 0.6f, 1.0f})
    for (const double theta : {0.0, 0.8, 1.3, 1.5}) {
      const Vec3 r = coated_furnace(coated(1.0f, coat_rough), hit_from(direction(theta, 0.4)), 8);
      EXPECT_LE(r.x, 1.0f + 0.01f) << coat_rough << " " << theta;
      EXPECT_GE(r.x, 0.98f) << coat_rough << " " << theta;
    }
}

TEST(PrincipledCoat, DrawnLobesAverageToTheWholeCoatedBsdf) {
  // One lobe is drawn per hit (the coat with probability weight / 2); the value the integrator
  // evaluates for a light's direction, averaged over the draws, is the whole BSDF: the coat's
  // compensated lobe times its weight, plus what lies below scaled by the coat's leave. 64
  // stratified draws split exactly, so this holds to rounding.
  const float weight = 1.0f, coat_rough = 0.4f;
  const ShadingPoint hit = hit_from(direction(1.1, 0.3));
  const Principled m = coated(weight, coat_rough, Vec3(0.6f, 0.3f, 0.1f));
  const Scatter bare = scatter(coated(0.0f, coat_rough, Vec3(0.6f, 0.3f, 0.1f)), hit, kContext);
  const float mu = float(std::cos(1.1));
  const CoatLayer layer = coat_layer(weight, coat_rough, 1.5f, 0.04f, Vec3(1.0f), mu);
  GlossyLobe coat = bare.glossy;
  coat.alpha = coat_rough * coat_rough;
  coat.fresnel = LobeFresnel::Dielectric;
  coat.f0 = Vec3(0.04f);
  coat.ior = 1.5f;
  coat.ior_f0 = 0.04f;
  coat.tint = Vec3(weight * layer.lobe_scale);
  for (const Vec3& wi : {direction(0.3, 2.0), direction(1.0, 3.5), direction(0.6, 0.1)}) {
    const Vec3 want = evaluate_lobe(coat, wi).f + layer.below * (evaluate_lobe(bare.glossy, wi).f + bare.f);
    Vec3 mean(0.0f);
    constexpr int kDraws = 64;
    for (int k = 0; k < kDraws; ++k) {
      MaterialContext ctx = kContext;
      ctx.sample = uint32_t(k);
      ctx.lobe_dimension = 7;
      const Scatter sc = scatter(m, hit, ctx);
      mean += (evaluate_lobe(sc.glossy, wi).f + sc.f) / float(kDraws);
    }
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean[c], want[c], 1e-4f * want[c]) << c;
  }
}
