// The Glossy Color pass's per-lobe values (render/glossy_color.h) against closed forms and
// Cycles' own table (src/scene/shader.tables, table_ggx_gen_schlick_s, Blender 5.0).
#include "render/glossy_color.h"

#include "materials/fresnel.h"
#include "materials/glossy.h"
#include "sampling/ggx_albedo.h"

#include <gtest/gtest.h>

#include <cmath>

namespace toyrt {
namespace {

GlossyLobe lobe_at(float roughness, float mu) {
  const ShadingPoint s{Vec3(std::sqrt(1.0f - mu * mu), 0.0f, mu), Vec3(0, 0, 1), Vec3(0, 0, 1), Vec2(0.0f)};
  return oriented_lobe(s, roughness, GgxShadowing::HeightCorrelated);
}

TEST(GlossyColor, AGlossyBsdfGivesItsColourExactly) {
  GlossyLobe lobe = lobe_at(0.3f, 0.7f);
  lobe.tint = Vec3(0.9f, 0.5f, 0.1f);
  EXPECT_EQ(lobe_albedo(lobe), Vec3(0.9f, 0.5f, 0.1f));
  Glossy g;
  EXPECT_EQ(glossy_pass_color(g, lobe), lobe.tint);
}

TEST(GlossyColor, MultiscatterKeepsCyclesShareOfTheEnergyScaleAndAWhiteLobeIsOne) {
  // Cycles' weight holds (1 + F_ms (1 - E) / E) / (1 + (1 - E) / E) of the scale: 1 for white.
  Glossy m = Glossy::make(Vec3(1.0f), 0.6f, GgxShadowing::HeightCorrelated, true);
  const ShadingPoint s{glm::normalize(Vec3(0.5f, 0.0f, 1.0f)), Vec3(0, 0, 1), Vec3(0, 0, 1), Vec2(0.0f)};
  const Scatter white = scatter(m, s, MaterialContext{});
  EXPECT_GT(white.glossy.tint.x, 1.05f);  // the energy scale is in TOYRT's tint
  EXPECT_NEAR(glossy_pass_color(m, white.glossy).x, 1.0f, 1e-5f);
  m.color = Vec3(0.5f);
  const Scatter grey = scatter(m, s, MaterialContext{});
  const float e = ggx_albedo(0.6f, grey.glossy.wo.z), missing = (1.0f - e) / e, e_avg = ggx_average_albedo(0.6f);
  const float f_ms = 0.5f * e_avg / (1.0f - 0.5f * (1.0f - e_avg));
  EXPECT_NEAR(glossy_pass_color(m, grey.glossy).x, 0.5f * (1.0f + f_ms * missing) / (1.0f + missing), 1e-5f);
  m.multiscatter = false;
  EXPECT_EQ(glossy_pass_color(m, scatter(m, s, MaterialContext{}).glossy), Vec3(0.5f));
}

TEST(GlossyColor, AMetalAtNormalIncidenceOnASmoothSurfaceIsItsF0) {
  GlossyLobe lobe = lobe_at(0.0f, 1.0f);
  lobe.tint = Vec3(1.0f);
  lobe.fresnel = LobeFresnel::F82Tint;
  lobe.f0 = Vec3(0.95f, 0.64f, 0.54f);
  lobe.f82_b = f82_tint_b(lobe.f0, Vec3(1.0f));
  EXPECT_NEAR(glm::distance(lobe_albedo(lobe), lobe.f0), 0.0f, 1e-4f);
}

TEST(GlossyColor, ADielectricLayerAtNormalIncidenceIsItsF0AndTheBlendGrowsTowardsGrazing) {
  GlossyLobe lobe = lobe_at(0.0f, 1.0f);
  lobe.tint = Vec3(1.0f);
  lobe.fresnel = LobeFresnel::Dielectric;
  lobe.ior = 1.5f;
  lobe.ior_f0 = f0_from_ior(1.5f);
  lobe.f0 = Vec3(lobe.ior_f0);
  EXPECT_NEAR(lobe_albedo(lobe).x, 0.04f, 2e-3f);  // F0 of IOR 1.5
  GlossyLobe grazing = lobe_at(0.0f, 0.2f);
  grazing.tint = lobe.tint;
  grazing.fresnel = lobe.fresnel;
  grazing.ior = lobe.ior;
  grazing.ior_f0 = lobe.ior_f0;
  grazing.f0 = lobe.f0;
  // A smooth surface reflects the mirror direction: the dielectric curve itself at cos 0.2.
  EXPECT_NEAR(lobe_albedo(grazing).x, fresnel_dielectric(0.2f, 1.5f), 0.02f);
}

TEST(GlossyColor, TheSchlickBlendOfASmoothLobeIsTheClosedForm) {
  for (float mu : {1.0f, 0.8f, 0.5f, 0.25f})
    EXPECT_NEAR(estimate_schlick_blend(0.0f, mu, 5.0f, 8), std::pow(1.0f - mu, 5.0f), 1e-5f) << mu;
}

TEST(GlossyColor, TheSchlickBlendTableIsCyclesAtItsMetalsZ) {
  // (roughness, cos_o) on the table's grid and Cycles' value there: the mean of its slices 7 and 8.
  struct Entry {
    int x, y;
    float cycles;
  };
  for (const Entry e : {Entry{8, 8, 0.0231935f}, Entry{15, 4, 0.0197835f}, Entry{4, 2, 0.3661255f},
                        Entry{15, 15, 0.0002195f}, Entry{2, 12, 0.0005325f}}) {
    const float s = schlick_blend(float(e.x) / 15.0f, float(e.y) / 15.0f);
    EXPECT_NEAR(s, e.cycles, 2e-3f + 0.02f * e.cycles) << e.x << ", " << e.y;
  }
}

TEST(GlossyColor, GlassCountsItsReflectionAndRefractionNone) {
  // Head-on, smooth, from outside: F0 of the IOR; from inside past the critical angle: 1 (total
  // internal reflection); Blender 3.x's macro Fresnel: the curve at cos_o itself, rough or not.
  const Material glass = FresnelDielectric::make(1.5f);
  const ShadingPoint head_on{Vec3(0, 0, 1), Vec3(0, 0, 1), Vec3(0, 0, 1), Vec2(0.0f)};
  EXPECT_NEAR(glass_pass_color(glass, head_on).x, f0_from_ior(1.5f), 1e-3f);
  const ShadingPoint inside{glm::normalize(Vec3(1.0f, 0.0f, -0.3f)), Vec3(0, 0, 1), Vec3(0, 0, 1), Vec2(0.0f)};
  EXPECT_EQ(glass_pass_color(glass, inside), Vec3(1.0f));
  const ShadingPoint oblique{glm::normalize(Vec3(1.0f, 0.0f, 1.0f)), Vec3(0, 0, 1), Vec3(0, 0, 1), Vec2(0.0f)};
  for (const float roughness : {0.0f, 0.4f}) {
    const Material glass3 = FresnelDielectric::make(1.5f, DielectricRoughness{roughness}, true);
    EXPECT_FLOAT_EQ(glass_pass_color(glass3, oblique).x, fresnel_dielectric(std::sqrt(0.5f), 1.5f)) << roughness;
  }
  // 4.0+, rough: the blend grows towards grazing, above the smooth curve's F0 head-on.
  const Material rough = FresnelDielectric::make(1.5f, DielectricRoughness{0.5f});
  EXPECT_GT(glass_pass_color(rough, head_on).x, f0_from_ior(1.5f));
  EXPECT_GT(glass_pass_color(rough, oblique).x, glass_pass_color(rough, head_on).x);
  EXPECT_EQ(glass_pass_color(Material(PerfectRefraction::make(1.5f)), oblique), Vec3(0.0f));
  EXPECT_EQ(glass_pass_color(Material(Lambert{}), oblique), Vec3(0.0f));
}

TEST(GlossyColor, BlenderThreesPrincipledWritesItsClosureWeight) {
  Principled m;
  m.layered = false;
  GlossyLobe lobe = lobe_at(0.4f, 0.6f);
  lobe.fresnel = LobeFresnel::Dielectric;
  lobe.f0 = Vec3(0.2f);
  lobe.tint = Vec3(1.0f);
  EXPECT_EQ(glossy_pass_color(m, lobe), Vec3(1.0f));
  m.layered = true;
  EXPECT_LT(glossy_pass_color(m, lobe).x, 1.0f);
}

}  // namespace
}  // namespace toyrt
