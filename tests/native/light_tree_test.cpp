// The light tree (lights/light_tree.h) against what a light selector must be: probabilities that
// sum to one (less the mass of branches no light below can use, which select() reports as "no
// light" just as often), select()'s frequencies equal to probability(), and probability() equal
// to what select() returned bit for bit; a positive probability for every light that can
// contribute and zero for clusters the bounds prove cannot (spots aimed away included); the
// one-sample estimate converging to the closed-form irradiance of hundreds of lights, and of a
// square split into 1,600 lamps; a variance far below uniform selection near one bright light;
// and builds of degenerate light sets. The scene builds it at commit.
#include "lights/light_tree.h"
#include "lights/light.h"
#include "lights/light_selector.h"
#include "render/renderer.h"
#include "sampling/rng.h"

#include "light_estimates.h"
#include "render_fixtures.h"

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <vector>

using namespace toyrt;
using namespace toyrt::testing;

namespace {

// A receiver somewhere over the lights' plane, its normal anywhere but mostly up.
struct Receiver {
  Vec3 p, n;
};
Receiver receiver(uint32_t j, uint32_t seed) {
  const auto r = [&](uint32_t d) { return random_float(j, 1, d, seed); };
  const Vec3 p(24.0f * r(0) - 12.0f, 24.0f * r(1) - 12.0f, 2.0f * r(2) - 0.5f);
  const Vec3 n = glm::normalize(Vec3(2.0f * r(3) - 1.0f, 2.0f * r(4) - 1.0f, 1.5f * r(5)));
  return {p, n};
}

// A binomial count's deviation allowed from its mean (6 standard deviations, plus one).
double binomial_slack(double n, double probability) {
  return 6.0 * std::sqrt(n * probability * (1.0 - probability)) + 1.0;
}

}  // namespace

class LightTreeLeaves : public ::testing::TestWithParam<uint32_t> {};  // lights per leaf
INSTANTIATE_TEST_SUITE_P(LightTree, LightTreeLeaves, ::testing::Values(1u, LightTree::kLeafSize));

TEST_P(LightTreeLeaves, SelectMatchesProbabilityAndTheProbabilitiesSumToOne) {
  const std::vector<Light> lights = mixed_lights(300, 1);
  const LightTree tree(lights, GetParam());
  ASSERT_EQ(tree.light_count(), lights.size());
  constexpr int kN = 40000;
  for (uint32_t j = 0; j < 12; ++j) {
    const Receiver at = receiver(j, 2);
    double sum = 0.0;
    std::vector<double> expected(lights.size());
    for (size_t i = 0; i < lights.size(); ++i) sum += expected[i] = tree.probability(lights.data(), at.p, at.n, i);
    std::vector<double> counts(lights.size(), 0.0);
    double none = 0.0;
    for (uint32_t k = 0; k < kN; ++k) {
      const LightSelection s = tree.select(lights.data(), at.p, at.n, random_float(k, j, 0, 3));
      if (!s.found()) {
        none += 1.0;
        continue;
      }
      // The same product of the same floats, not merely close.
      ASSERT_EQ(s.probability, tree.probability(lights.data(), at.p, at.n, size_t(s.index))) << s.index;
      ASSERT_GT(s.probability, 0.0f);
      counts[size_t(s.index)] += 1.0;
    }
    // What the probabilities miss is the mass of dead ends (a cluster passes its bound, both its
    // children fail theirs), and select() finds no light exactly that often.
    EXPECT_LE(sum, 1.0 + 1e-5);
    EXPECT_NEAR(none, kN * (1.0 - sum), binomial_slack(kN, std::max(0.0, 1.0 - sum)) + 1e-5 * kN);
    for (size_t i = 0; i < lights.size(); ++i)
      EXPECT_NEAR(counts[i], kN * expected[i], binomial_slack(kN, expected[i])) << "light " << i << " at " << j;
  }
}

TEST(LightTree, WithoutAReceiverCosineEveryBranchCanBeTakenAndTheProbabilitiesSumToOne) {
  // Point lights bound no direction, so with n = 0 no cluster's bound fails: no dead end.
  std::vector<Light> lights;
  for (uint32_t i = 0; i < 500; ++i)
    lights.emplace_back(PointLight::make(
        Vec3(100.0f * random_float(i, 0, 0, 4), 10.0f * random_float(i, 0, 1, 4), random_float(i, 0, 2, 4)),
        1.0f + 1000.0f * random_float(i, 0, 3, 4), Vec3(1.0f)));
  const LightTree tree(lights);
  for (uint32_t j = 0; j < 20; ++j) {
    const Vec3 p = receiver(j, 5).p * Vec3(5.0f, 1.0f, 1.0f);
    double sum = 0.0;
    for (size_t i = 0; i < lights.size(); ++i) sum += tree.probability(lights.data(), p, Vec3(0.0f), i);
    EXPECT_NEAR(sum, 1.0, 1e-5);
  }
}

TEST(LightTree, SpotsWhoseConesMissTheReceiverAreNeverEnteredAndTheProbabilitiesSumToOne) {
  // 64 spots 2 m up over [-1, 1]^2, pointing down with a 1 rad cone (0.5 rad half-angle), and 64
  // point lights 30 to 50 m away. A receiver 20 m aside is outside every cone (atan(19 / 2) is
  // 1.47 rad): the spots' clusters, bounded by their cones, must weigh zero, so every pick lands
  // on a point light and the probabilities sum to one. Bounded as point lights (the old bounds)
  // the spots' clusters were entered, then found empty: a "no light" pick, a sum below one.
  std::vector<Light> lights;
  for (uint32_t i = 0; i < 64; ++i) {
    SpotLight::Settings s;
    s.matrix = glm::translate(
        Mat4(1.0f), Vec3(2.0f * random_float(i, 0, 0, 9) - 1.0f, 2.0f * random_float(i, 0, 1, 9) - 1.0f, 2.0f));
    s.spot_size = 1.0f;
    s.power = 1000.0f;
    s.radius = i % 2 == 0 ? 0.0f : 0.1f;
    lights.emplace_back(SpotLight::make(s));
  }
  for (uint32_t i = 0; i < 64; ++i)
    lights.emplace_back(PointLight::make(Vec3(30.0f + 20.0f * random_float(i, 1, 0, 9),
                                              10.0f * random_float(i, 1, 1, 9), 1.0f + random_float(i, 1, 2, 9)),
                                         10.0f, Vec3(1.0f)));
  const LightTree tree(lights);
  for (const Vec3& p : {Vec3(20.0f, 0.0f, 0.0f), Vec3(20.0f, 5.0f, 0.5f), Vec3(-20.0f, 0.0f, 0.0f)}) {
    double sum = 0.0, spots = 0.0;
    for (size_t i = 0; i < lights.size(); ++i) {
      const float probability = tree.probability(lights.data(), p, Vec3(0, 0, 1), i);
      sum += probability;
      if (i < 64) spots += probability;
    }
    EXPECT_EQ(spots, 0.0) << p.x;
    EXPECT_NEAR(sum, 1.0, 1e-5) << p.x;
  }
  // Under the spots, where their cones reach, they are picked (and the sum is one there too).
  double under = 0.0;
  for (size_t i = 0; i < 64; ++i) under += tree.probability(lights.data(), Vec3(0.0f), Vec3(0, 0, 1), i);
  EXPECT_GT(under, 0.9);
}

// The irradiance at a point h below a corner of a w x l rectangle of radiance L facing it,
// parallel to its plane: pi L times the form factor (Howell's catalogue, C-11).
double corner_rectangle_irradiance(double L, double w, double l, double h) {
  const double x = w / h, y = l / h;
  return L / 2.0 *
         (x / std::sqrt(1 + x * x) * std::atan(y / std::sqrt(1 + x * x)) +
          y / std::sqrt(1 + y * y) * std::atan(x / std::sqrt(1 + y * y)));
}

TEST(LightTree, AUniformSquareSplitIntoSixteenHundredLampsHasTheWholeSquaresClosedFormIrradiance) {
  // A 1 m square 0.5 m up, facing down, as 40 x 40 square lamps of one radiance: through the
  // tree (1,600 lamps), the one-sample estimate at points under it converges to the closed form
  // of the whole square (four corner rectangles around the point), and the probabilities of all
  // lamps sum to one.
  constexpr int kSide = 40;
  constexpr float kCell = 1.0f / kSide, kHeight = 0.5f;
  std::vector<Light> lights;
  for (int i = 0; i < kSide; ++i)
    for (int j = 0; j < kSide; ++j)
      lights.emplace_back(AreaLight::make(AreaShape::Square, kCell, kCell,
                                          glm::translate(Mat4(1.0f), Vec3(-0.5f + (float(i) + 0.5f) * kCell,
                                                                          -0.5f + (float(j) + 0.5f) * kCell, kHeight)),
                                          10.0f, Vec3(1.0f)));
  const double L = std::get<AreaLight>(lights[0]).radiance.x;
  const LightTree tree(lights);
  const Vec3 up(0, 0, 1);
  for (const Vec3& p : {Vec3(0.0f), Vec3(0.3f, -0.2f, 0.0f)}) {
    double closed = 0.0;
    for (double w : {0.5 - double(p.x), 0.5 + double(p.x)})
      for (double l : {0.5 - double(p.y), 0.5 + double(p.y)}) closed += corner_rectangle_irradiance(L, w, l, kHeight);
    double sum = 0.0;
    for (size_t i = 0; i < lights.size(); ++i) sum += tree.probability(lights.data(), p, up, i);
    EXPECT_NEAR(sum, 1.0, 1e-5);
    const Estimate e = monte_carlo(40000, [&](uint32_t k) {
      const LightSelection pick = tree.select(lights.data(), p, up, random_float(k, 0, 0, 11));
      if (!pick.found()) return 0.0;
      return irradiance_sample(lights[size_t(pick.index)], p, up, rand2(k, 12)) / pick.probability;
    });
    EXPECT_NEAR(e.mean, closed, 4.0 * e.standard_error + 1e-3 * closed) << p.x << " " << e.standard_error;
  }
}

TEST_P(LightTreeLeaves, EveryLightThatCanContributeHasAPositiveProbability) {
  const std::vector<Light> lights = mixed_lights(400, 6);
  const LightTree tree(lights, GetParam());
  int contributing = 0, behind = 0;
  for (uint32_t j = 0; j < 60; ++j) {
    const Receiver at = receiver(j, 7);
    for (size_t i = 0; i < lights.size(); ++i) {
      bool contributes = false;
      for (uint32_t k = 0; k < 16 && !contributes; ++k)
        contributes = irradiance_sample(lights[i], at.p, at.n, rand2(k, 8 + j)) > 0.0;
      const float probability = tree.probability(lights.data(), at.p, at.n, i);
      if (contributes) {
        ++contributing;
        EXPECT_GT(probability, 0.0f) << "light " << i << " at receiver " << j;
      }
      if (light_importance(lights[i], at.p, at.n) == 0.0f) {
        ++behind;
        EXPECT_EQ(probability, 0.0f) << "light " << i << " at receiver " << j;  // its leaf's weight is 0
      }
    }
  }
  EXPECT_GT(contributing, 5000);
  EXPECT_GT(behind, 2000);
}

TEST_P(LightTreeLeaves, AClusterWhollyBelowTheReceiversPlaneIsNeverEntered) {
  // 100 lights in a ball 5 m below a floor facing up, 100 above: the bound of the lower cluster
  // fails at the root's children, so none of it is chosen or even weighed.
  std::vector<Light> lights;
  for (uint32_t i = 0; i < 200; ++i) {
    const Vec3 offset(random_float(i, 0, 0, 9), random_float(i, 0, 1, 9), random_float(i, 0, 2, 9));
    const float z = i < 100 ? -5.0f : 5.0f;
    lights.emplace_back(PointLight::make(Vec3(0.0f, 0.0f, z) + offset - Vec3(0.5f), 10.0f, Vec3(1.0f)));
  }
  const LightTree tree(lights, GetParam());
  const Vec3 p(0.3f, -0.2f, 0.0f), n(0, 0, 1);
  for (size_t i = 0; i < 100; ++i) EXPECT_EQ(tree.probability(lights.data(), p, n, i), 0.0f);
  double sum = 0.0;
  for (size_t i = 100; i < 200; ++i) sum += tree.probability(lights.data(), p, n, i);
  EXPECT_NEAR(sum, 1.0, 1e-5);
  for (uint32_t k = 0; k < 10000; ++k) {
    const LightSelection s = tree.select(lights.data(), p, n, random_float(k, 0, 0, 10));
    ASSERT_TRUE(s.found());
    EXPECT_GE(s.index, 100);
  }
}

TEST_P(LightTreeLeaves, LightsNotLinkedToTheReceiversSetAreLeftOutByTheTreeAndTheLinearWalk) {
  // 300 point lights over a floor facing up (every one reaches it); one in three lights only
  // receiver set 5 (light linking). For a receiver in set 2 those never come out and weigh 0, the
  // rest share all the probability; in set 5 the tree answers exactly as an unlinked tree does.
  std::vector<Light> lights;
  std::vector<uint64_t> sets;
  for (uint32_t i = 0; i < 300; ++i) {
    const Vec3 pos(20.0f * random_float(i, 0, 0, 12) - 10.0f, 20.0f * random_float(i, 0, 1, 12) - 10.0f,
                   0.5f + 3.0f * random_float(i, 0, 2, 12));
    lights.emplace_back(PointLight::make(pos, 1.0f + 50.0f * random_float(i, 0, 3, 12), Vec3(1.0f)));
    sets.push_back(i % 3 == 0 ? uint64_t(1) << 5 : kAllLightSets);
  }
  LightTree tree(lights, GetParam());
  const LightTree unlinked(lights, GetParam());
  tree.set_receiver_sets(sets);
  const LightSelector walk(lights, nullptr, sets.data());
  const Vec3 p(0.7f, -1.3f, 0.0f), n(0, 0, 1);
  double through_tree = 0.0, linear = 0.0;
  for (size_t i = 0; i < lights.size(); ++i) {
    const float t = tree.probability(lights.data(), p, n, i, 2), w = walk.probability(p, n, i, 2);
    if (i % 3 == 0) {
      EXPECT_EQ(t, 0.0f) << i;
      EXPECT_EQ(w, 0.0f) << i;
    } else {
      EXPECT_GT(t, 0.0f) << i;
      EXPECT_GT(w, 0.0f) << i;
    }
    through_tree += t;
    linear += w;
    EXPECT_EQ(tree.probability(lights.data(), p, n, i, 5), unlinked.probability(lights.data(), p, n, i)) << i;
  }
  EXPECT_NEAR(through_tree, 1.0, 1e-5);
  EXPECT_NEAR(linear, 1.0, 1e-5);
  for (uint32_t k = 0; k < 5000; ++k) {
    const float u = random_float(k, 0, 0, 13);
    for (const LightSelection& s : {tree.select(lights.data(), p, n, u, 2), walk.select(p, n, u, 2)}) {
      ASSERT_TRUE(s.found());
      ASSERT_NE(s.index % 3, 0) << s.index;
    }
    const LightSelection s = tree.select(lights.data(), p, n, u, 2);
    ASSERT_EQ(s.probability, tree.probability(lights.data(), p, n, size_t(s.index), 2));
  }
}

TEST_P(LightTreeLeaves, OneSampleEstimateConvergesToTheSumOfTwoHundredLightsIrradiance) {
  // 200 point lights of radius 0 and a sun over a floor facing up: E = sum of I cos / r^2 over
  // those above it, plus S cos for the sun.
  std::vector<Light> lights;
  const Vec3 p(0.7f, -1.3f, 0.0f), n(0, 0, 1);
  double exact = 0.0;
  for (uint32_t i = 0; i < 200; ++i) {
    const Vec3 pos(20.0f * random_float(i, 0, 0, 11) - 10.0f, 20.0f * random_float(i, 0, 1, 11) - 10.0f,
                   4.0f * random_float(i, 0, 2, 11) - 1.0f);
    const float power = 1.0f + 200.0f * random_float(i, 0, 3, 11);
    lights.emplace_back(PointLight::make(pos, power, Vec3(1.0f)));
    const Vec3 d = pos - p;
    const double r2 = glm::dot(d, d), cos = d.z / std::sqrt(r2);
    if (cos > 0.0) exact += power / (4.0 * kPiD) * cos / r2;
  }
  SunLight::Settings sun;
  sun.matrix = glm::rotate(Mat4(1.0f), 0.5f, Vec3(1, 0, 0));
  sun.strength = 2.0f;
  sun.angle = 0.0f;
  lights.emplace_back(SunLight::make(sun));
  exact += 2.0 * std::cos(0.5);
  const LightTree tree(lights, GetParam());
  const Estimate e = monte_carlo(400000, [&](uint32_t i) {
    const LightSelection s = tree.select(lights.data(), p, n, random_float(i, 0, 2, 12));
    if (!s.found()) return 0.0;
    return irradiance_sample(lights[size_t(s.index)], p, n, rand2(i, 12)) / s.probability;
  });
  expect_converges(e, exact, "light tree");
  EXPECT_LT(e.standard_error, 0.02 * exact);  // and it got there
}

TEST(LightTree, NearOneBrightLightAmongHundredsOfDimOnesItsVarianceIsFarBelowUniformSelection) {
  // A 100 W light 0.5 m above the receiver, 500 lights of 1 W 20 to 50 m away: uniform selection
  // finds the bright light once in 501 picks; the tree almost always.
  std::vector<Light> lights;
  const Vec3 p(0.0f), n(0, 0, 1);
  lights.emplace_back(PointLight::make(Vec3(0.1f, 0.0f, 0.5f), 100.0f, Vec3(1.0f)));
  for (uint32_t i = 0; i < 500; ++i) {
    const float angle = 2.0f * kPi * random_float(i, 0, 0, 13), radius = 20.0f + 30.0f * random_float(i, 0, 1, 13);
    lights.emplace_back(PointLight::make(
        Vec3(radius * std::cos(angle), radius * std::sin(angle), 1.0f + 5.0f * random_float(i, 0, 2, 13)), 1.0f,
        Vec3(1.0f)));
  }
  const LightTree tree(lights);
  const auto variance = [&](const std::function<LightSelection(float)>& pick) {
    double sum = 0.0, sum2 = 0.0;
    constexpr int kN = 200000;
    for (uint32_t i = 0; i < kN; ++i) {
      const LightSelection s = pick(random_float(i, 0, 0, 14));
      const double x = s.found() ? irradiance_sample(lights[size_t(s.index)], p, n, rand2(i, 14)) / s.probability : 0.0;
      sum += x;
      sum2 += x * x;
    }
    return sum2 / kN - (sum / kN) * (sum / kN);
  };
  const double with_tree = variance([&](float u) { return tree.select(lights.data(), p, n, u); });
  const double uniform = variance([&](float u) {
    return LightSelection{int32_t(std::min(size_t(u * float(lights.size())), lights.size() - 1)),
                          1.0f / float(lights.size())};
  });
  RecordProperty("variance_ratio", std::to_string(uniform / with_tree));
  EXPECT_LT(with_tree * 100.0, uniform) << "uniform " << uniform << ", tree " << with_tree;
}

TEST(LightTree, BuildsOnNoneOneTwoAndCoincidentLights) {
  const Vec3 p(0.0f), n(0, 0, 1);
  const LightTree none{std::vector<Light>{}};
  EXPECT_EQ(none.node_count(), 0u);
  EXPECT_FALSE(none.select(static_cast<const Light*>(nullptr), p, n, 0.5f).found());
  EXPECT_EQ(none.probability(static_cast<const Light*>(nullptr), p, n, 0), 0.0f);

  const std::vector<Light> one = {PointLight::make(Vec3(0, 0, 1), 10.0f, Vec3(1.0f))};
  const LightTree tree_one(one);
  EXPECT_EQ(tree_one.node_count(), 1u);
  EXPECT_EQ(tree_one.select(one.data(), p, n, 0.7f).probability, 1.0f);
  EXPECT_EQ(tree_one.probability(one.data(), p, -n, 0), 0.0f);  // below the receiver

  const std::vector<Light> two = {PointLight::make(Vec3(0, 0, 1), 10.0f, Vec3(1.0f)),
                                  PointLight::make(Vec3(0, 0, 2), 10.0f, Vec3(1.0f))};
  // Two lights in one leaf, and in two (leaf size 1): each weighs by its own importance, 1 / 1
  // against 1 / 4.
  for (uint32_t leaf_size : {LightTree::kLeafSize, 1u}) {
    const LightTree tree_two(two, leaf_size);
    EXPECT_EQ(tree_two.node_count(), leaf_size == 1 ? 3u : 1u);
    EXPECT_NEAR(tree_two.probability(two.data(), p, n, 0), 0.8f, 1e-6f);
    EXPECT_NEAR(tree_two.probability(two.data(), p, n, 1), 0.2f, 1e-6f);
  }

  // 1000 lights at one position (and 1000 of power 0 there): no plane separates them, so the
  // build halves them by count: a balanced tree, every light equally likely, no NaN.
  std::vector<Light> same(1000, Light(PointLight::make(Vec3(1, 2, 3), 5.0f, Vec3(1.0f))));
  for (int i = 0; i < 1000; ++i) same.emplace_back(PointLight::make(Vec3(1, 2, 3), 0.0f, Vec3(1.0f)));
  const LightTree tree_same(same, 1);
  EXPECT_EQ(tree_same.node_count(), 2 * same.size() - 1);
  EXPECT_LE(tree_same.depth(), 11);  // ceil(log2(2000))
  for (size_t i = 0; i < same.size(); ++i) {
    const float probability = tree_same.probability(same.data(), p, n, i);
    ASSERT_TRUE(std::isfinite(probability));
    if (i < 1000)
      EXPECT_NEAR(probability, 1e-3f, 1e-8f);
    else
      EXPECT_EQ(probability, 0.0f);
  }
  for (float u : {0.0f, 0.3f, 0x1.fffffep-1f}) {
    const LightSelection s = tree_same.select(same.data(), p, n, u);
    ASSERT_TRUE(s.found());
    EXPECT_LT(s.index, 1000);
  }
}

TEST(LightTree, TheSceneBuildsItAtCommitForMoreThanTheThresholdOfLights) {
  Scene scene = floor_of(Lambert{Vec3(0.5f), -1});
  for (size_t i = 0; i < kLightTreeFrom; ++i)
    scene.add_light(PointLight::make(Vec3(float(i), 0.0f, 1.0f), 10.0f, Vec3(1.0f)));
  scene.commit();
  EXPECT_EQ(scene.light_tree(), nullptr);  // few lights: the linear walk
  scene.add_light(PointLight::make(Vec3(0.0f, 1.0f, 1.0f), 10.0f, Vec3(1.0f)));
  EXPECT_EQ(scene.light_tree(), nullptr);  // edited since the commit: linear until the next
  scene.commit();
  ASSERT_NE(scene.light_tree(), nullptr);
  EXPECT_EQ(scene.light_tree()->light_count(), kLightTreeFrom + 1);
  EXPECT_GT(scene.commit_stats().light_tree_nodes, 0u);
  scene.commit();  // nothing changed in the lights: the same tree, not rebuilt
  EXPECT_EQ(scene.commit_stats().light_tree_ms, 0.0);
  ASSERT_NE(scene.light_tree(), nullptr);
}

TEST(LightTree, ARenderThroughTheTreeHasTheMeanOfARenderOfEveryLight) {
  // More point lights than the threshold over the Lambert floor: one light per hit through the
  // tree, and every light at every hit, render one pixel to the same mean within the noise.
  Scene scene = floor_of(Lambert{Vec3(0.8f), -1});
  for (uint32_t i = 0; i < kLightTreeFrom + 50; ++i)
    scene.add_light(
        PointLight::make(Vec3(8.0f * random_float(i, 0, 0, 15) - 4.0f, 8.0f * random_float(i, 0, 1, 15) - 4.0f,
                              0.3f + 3.0f * random_float(i, 0, 2, 15)),
                         1.0f + 50.0f * random_float(i, 0, 3, 15), Vec3(1.0f)));
  scene.commit();
  ASSERT_NE(scene.light_tree(), nullptr);
  RenderSettings one = few_samples(20000), all = few_samples(16);
  one.integrator.light_sampling = LightSampling::One;
  all.integrator.light_sampling = LightSampling::All;
  const double exact = render(scene, pixel_above(1e-3f), all).rgba[0];
  const double tree = render(scene, pixel_above(1e-3f), one).rgba[0];
  EXPECT_NEAR(tree, exact, 0.02 * exact);
}
