// The Mix / Add Shader's draw (materials/material_mix.h): each input is chosen with probability
// proportional to its weight and carries weight / probability, so the expected weight of every
// leaf is its share of the mixed closure; and the view-dependent factors' closed forms.
#include "materials/material_mix.h"
#include "materials/fresnel.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace toyrt {
namespace {

MaterialMix mix_of(int32_t first, int32_t second, float fac, bool add = false) {
  MaterialMix m;
  m.active = true;
  m.first = first;
  m.second = second;
  m.fac = fac;
  m.add = add;
  return m;
}

// The expected weight of each leaf over a fine uniform grid of u: sum of weight x [leaf] / n.
std::vector<double> shares(const std::vector<MaterialMix>& mixes, int32_t root, size_t leaves) {
  std::vector<double> share(leaves, 0.0);
  const int n = 1 << 16;
  const MixPoint at{Vec2(0.0f), Vec3(0, 0, 1), Vec3(0, 0, 1), false};
  for (int i = 0; i < n; ++i) {
    const MixPick pick = pick_mixed(mixes, {}, root, at, (float(i) + 0.5f) / float(n));
    if (pick.leaf >= 0) share[size_t(pick.leaf)] += double(pick.weight) / n;
  }
  return share;
}

TEST(MaterialMix, EachLeafCarriesItsShareOfTheMix) {
  // Leaves 0, 1, 2; 3 = Mix(0, 1, 0.3); 4 = Mix(3, 2, 0.25); 5 = Add(0, 2); 6 = Mix(-1, 1, 0.6).
  std::vector<MaterialMix> mixes(7);
  mixes[3] = mix_of(0, 1, 0.3f);
  mixes[4] = mix_of(3, 2, 0.25f);
  mixes[5] = mix_of(0, 2, 0.0f, true);
  mixes[6] = mix_of(-1, 1, 0.6f);
  const std::vector<double> nested = shares(mixes, 4, 7);
  EXPECT_NEAR(nested[0], 0.75 * 0.7, 1e-4);
  EXPECT_NEAR(nested[1], 0.75 * 0.3, 1e-4);
  EXPECT_NEAR(nested[2], 0.25, 1e-4);
  const std::vector<double> added = shares(mixes, 5, 7);  // Add: both whole (Cycles' sum)
  EXPECT_NEAR(added[0], 1.0, 1e-4);
  EXPECT_NEAR(added[2], 1.0, 1e-4);
  const std::vector<double> black = shares(mixes, 6, 7);  // the unlinked input's 0.4 is black
  EXPECT_NEAR(black[1], 0.6, 1e-6);
  EXPECT_EQ(pick_mixed(mixes, {}, 1, MixPoint{}, 0.5f).leaf, 1);  // no mix: its own leaf
}

TEST(MaterialMix, FresnelFactorIsTheDielectricFresnelOfTheViewCosine) {
  MaterialMix m = mix_of(0, 1, 0.5f);
  m.factor = MixFactor::Fresnel;
  m.param = 1.5f;
  const float c = 0.6f;
  const Vec3 wo(std::sqrt(1.0f - c * c), 0.0f, c);
  EXPECT_NEAR(mix_factor(m, {}, MixPoint{Vec2(0.0f), wo, Vec3(0, 0, 1), false}), fresnel_dielectric(c, 1.5f), 1e-6);
  // From the back the index is inverted (Cycles' backfacing flip): beyond the critical angle, 1.
  EXPECT_NEAR(mix_factor(m, {}, MixPoint{Vec2(0.0f), wo, Vec3(0, 0, 1), true}), 1.0f, 1e-6);
  EXPECT_NEAR(mix_factor(m, {}, MixPoint{Vec2(0.0f), Vec3(0, 0, 1), Vec3(0, 0, 1), false}), 0.04f, 1e-6);
}

TEST(MaterialMix, LayerWeightFacingIsOneMinusTheCosineToTheBlendPower) {
  MaterialMix m = mix_of(0, 1, 0.5f);
  m.factor = MixFactor::LayerFacing;
  const float c = 0.6f;
  const MixPoint at{Vec2(0.0f), Vec3(0.8f, 0.0f, c), Vec3(0, 0, 1), false};
  m.param = 0.5f;
  EXPECT_NEAR(mix_factor(m, {}, at), 1.0f - c, 1e-6);
  m.param = 0.25f;  // exponent 2 x blend
  EXPECT_NEAR(mix_factor(m, {}, at), 1.0f - std::pow(c, 0.5f), 1e-6);
  m.param = 0.75f;  // exponent 0.5 / (1 - blend)
  EXPECT_NEAR(mix_factor(m, {}, at), 1.0f - std::pow(c, 2.0f), 1e-6);
}

}  // namespace
}  // namespace toyrt
