// The samplers against their known distributions: the counter-based RNG and the warps pass
// chi-square tests against their densities, the Sobol-Owen pattern is a (0,m,2)-net for every
// power of two of samples and integrates better than independent random numbers.
#include "sampling/frame.h"
#include "sampling/rng.h"
#include "sampling/sobol_owen.h"
#include "sampling/warp.h"

#include "statistics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

using namespace toyrt;
using toyrt::testing::chi_square_quantile;
using toyrt::testing::normal_upper_quantile;

namespace {

constexpr double kPiD = 3.14159265358979323846;

// Pearson's test of observed counts against bin probabilities, bins with fewer than 5 expected
// samples pooled (the chi-square approximation needs it). A bin of probability 0 must stay empty.
// alpha = 1e-4: the chance that a correct sampler fails (the inputs are fixed, so a passing test
// passes every time).
void expect_fits(const std::vector<double>& counts, const std::vector<double>& probabilities, double n,
                 const char* what, double alpha = 1e-4) {
  double chi2 = 0.0, pooled_observed = 0.0, pooled_expected = 0.0;
  int bins = 0;
  for (size_t i = 0; i < counts.size(); ++i) {
    const double expected = probabilities[i] * n;
    if (probabilities[i] <= 0.0) {
      EXPECT_EQ(counts[i], 0.0) << what << ": samples in bin " << i << " of zero probability";
      continue;
    }
    if (expected < 5.0) {
      pooled_observed += counts[i];
      pooled_expected += expected;
      continue;
    }
    chi2 += (counts[i] - expected) * (counts[i] - expected) / expected;
    ++bins;
  }
  if (pooled_expected > 0.0) {
    chi2 += (pooled_observed - pooled_expected) * (pooled_observed - pooled_expected) / pooled_expected;
    ++bins;
  }
  ASSERT_GE(bins, 11) << what;
  const double threshold = chi_square_quantile(bins - 1, alpha);
  EXPECT_LT(chi2, threshold) << what << ": chi-square " << chi2 << " over " << bins << " bins";
}

// Independent uniform pairs from the counter-based RNG.
Vec2 rand2(uint32_t i, uint32_t seed) { return {random_float(i, 0, 0, seed), random_float(i, 0, 1, seed)}; }

// Histogram of directions over a latitude-longitude grid (theta in [0, theta_max], phi in
// [0, 2 pi)) against a density that depends on theta only, integrated exactly per bin by
// `cdf_theta` (the probability of theta' < theta).
void expect_directions_fit(const std::function<Vec3(Vec2)>& sample, double theta_max,
                           const std::function<double(double)>& cdf_theta, const char* what) {
  constexpr int kTheta = 16, kPhi = 16, kN = 200000;
  std::vector<double> counts(kTheta * kPhi, 0.0), probabilities(kTheta * kPhi);
  for (int t = 0; t < kTheta; ++t)
    for (int p = 0; p < kPhi; ++p)
      probabilities[t * kPhi + p] =
          (cdf_theta(theta_max * (t + 1) / kTheta) - cdf_theta(theta_max * t / kTheta)) / kPhi;
  for (int i = 0; i < kN; ++i) {
    const Vec3 d = sample(rand2(i, 77));
    ASSERT_NEAR(glm::length(d), 1.0f, 1e-5f) << what;
    const double theta = std::acos(std::clamp(double(d.z), -1.0, 1.0));
    ASSERT_LE(theta, theta_max + 1e-3) << what;
    double phi = std::atan2(double(d.y), double(d.x));
    if (phi < 0.0) phi += 2.0 * kPiD;
    const int t = std::min(kTheta - 1, int(theta / theta_max * kTheta));
    const int p = std::min(kPhi - 1, int(phi / (2.0 * kPiD) * kPhi));
    counts[t * kPhi + p] += 1.0;
  }
  expect_fits(counts, probabilities, kN, what);
}

}  // namespace

TEST(SamplingStatistics, ChiSquareQuantileMatchesTheNormalLimit) {
  // The quantile routine itself: for large k, chi-square is nearly normal with mean k and
  // variance 2k, and the median of chi-square(k) is k (1 - 2/(9k))^3 to within 1e-3 relative.
  EXPECT_NEAR(normal_upper_quantile(0.5), 0.0, 1e-12);
  EXPECT_NEAR(normal_upper_quantile(0.025), 1.959963985, 1e-6);  // the textbook 95 % two-sided value
  const int k = 20000;
  EXPECT_NEAR(chi_square_quantile(k, 0.025), k + normal_upper_quantile(0.025) * std::sqrt(2.0 * k), 5.0);
}

TEST(SamplingRng, SameCountersGiveSameNumbersAndEveryCounterMatters) {
  int same_as_neighbour = 0;
  for (uint32_t i = 0; i < 1000; ++i) {
    const float v = random_float(i, 7, 3, 42);
    EXPECT_EQ(v, random_float(i, 7, 3, 42));
    EXPECT_GE(v, 0.0f);
    EXPECT_LT(v, 1.0f);
    same_as_neighbour += v == random_float(i + 1, 7, 3, 42);
    same_as_neighbour += v == random_float(i, 8, 3, 42);
    same_as_neighbour += v == random_float(i, 7, 4, 42);
    same_as_neighbour += v == random_float(i, 7, 3, 43);
  }
  // Each coincidence has probability 2^-24: 4000 comparisons should find none.
  EXPECT_EQ(same_as_neighbour, 0);
}

TEST(SamplingRng, UniformAlongEveryCounter) {
  constexpr int kBins = 64, kN = 100000;
  for (int counter = 0; counter < 4; ++counter) {
    std::vector<double> counts(kBins, 0.0), probabilities(kBins, 1.0 / kBins);
    for (uint32_t i = 0; i < kN; ++i) {
      const uint32_t k[4] = {counter == 0 ? i : 5u, counter == 1 ? i : 5u, counter == 2 ? i : 5u,
                             counter == 3 ? i : 5u};
      counts[int(random_float(k[0], k[1], k[2], k[3]) * kBins)] += 1.0;
    }
    expect_fits(counts, probabilities, kN, "rng along one counter");
  }
}

TEST(SamplingRng, ConsecutiveDimensionsAndPixelsAreIndependent) {
  constexpr int kGrid = 16, kN = 100000;
  std::vector<double> dims(kGrid * kGrid, 0.0), pixels(kGrid * kGrid, 0.0),
      probabilities(kGrid * kGrid, 1.0 / (kGrid * kGrid));
  for (uint32_t i = 0; i < kN; ++i) {
    const Vec2 a = rand2(i, 9);
    dims[int(a.x * kGrid) * kGrid + int(a.y * kGrid)] += 1.0;
    const float b = random_float(2 * i, 0, 0, 9), c = random_float(2 * i + 1, 0, 0, 9);
    pixels[int(b * kGrid) * kGrid + int(c * kGrid)] += 1.0;
  }
  expect_fits(dims, probabilities, kN, "pairs of dimensions");
  expect_fits(pixels, probabilities, kN, "pairs of neighbouring pixels");
}

TEST(SamplingSobolOwen, FastFormsEqualTheirDefinitions) {
  // The definitions, one bit at a time: the reversal, and dimension 1 as the sum of the direction
  // numbers v_0 = 1/2, v_k = v_{k-1} ^ (v_{k-1} >> 1) of the index's set bits.
  auto reversed = [](uint32_t x) {
    uint32_t r = 0;
    for (int i = 0; i < 32; ++i) r |= (x >> i & 1u) << (31 - i);
    return r;
  };
  auto dimension1 = [](uint32_t index) {
    uint32_t result = 0;
    for (uint32_t v = 1u << 31; index != 0; index >>= 1, v ^= v >> 1)
      if (index & 1u) result ^= v;
    return result;
  };
  std::vector<uint32_t> xs;
  for (uint32_t i = 0; i < (1u << 16); ++i) xs.push_back(i);
  for (uint32_t i = 0; i < 100000; ++i) xs.push_back(pcg_hash(i));
  for (int bit = 0; bit < 32; ++bit) xs.push_back(1u << bit), xs.push_back(~0u >> bit);
  for (size_t k = 0; k < xs.size(); ++k) {
    const uint32_t x = xs[k], seed = pcg_hash(uint32_t(k) ^ 0x9e3779b9u);
    ASSERT_EQ(reverse_bits(x), reversed(x)) << x;
    ASSERT_EQ(sobol_dimension1(x), dimension1(x)) << x;
    ASSERT_EQ(sobol_dimension1_reversed(x), reversed(dimension1(x))) << x;
    // sobol_owen_2d and _1d skip the two reversals that cancel in this composition.
    ASSERT_EQ(nested_uniform_scramble(sobol_dimension0(x), seed), reverse_bits(laine_karras_permutation(x, seed)));
    ASSERT_EQ(nested_uniform_scramble(sobol_dimension1(x), seed),
              reverse_bits(laine_karras_permutation(sobol_dimension1_reversed(x), seed)));
  }
}

TEST(SamplingSobolOwen, SamplersAreTheScrambledSobolDimensionsOfTheShuffledIndex) {
  // The samplers' definition, composed from its parts: the sample index shuffled by a nested
  // scramble keyed by (pixel, dimension, seed), then x = Sobol dimension 0 and y = dimension 1 of
  // it, each scrambled with its own key (the 1D sampler: dimension 0 with a third key). The fast
  // forms above are checked on their own; this checks the wiring (which dimension and which key
  // goes to x and to y): a swap of either fails it.
  for (uint32_t pixel : {0u, 7u, 4096u, 999999u})
    for (uint32_t dimension : {0u, 1u, 9u})
      for (uint32_t seed : {0u, 3u})
        for (uint32_t sample = 0; sample < 4096; sample += 37) {
          const uint32_t key2 = hash_keys(pixel, dimension, seed, 0x736f626cu);
          const uint32_t index2 = nested_uniform_scramble(sample, key2);
          const Vec2 p = sobol_owen_2d(pixel, sample, dimension, seed);
          ASSERT_EQ(p.x, bits_to_unit_float(nested_uniform_scramble(sobol_dimension0(index2), pcg_hash(key2 ^ 0x1u))));
          ASSERT_EQ(p.y, bits_to_unit_float(nested_uniform_scramble(sobol_dimension1(index2), pcg_hash(key2 ^ 0x2u))));
          const uint32_t key1 = hash_keys(pixel, dimension, seed, 0x31646f77u);
          const uint32_t index1 = nested_uniform_scramble(sample, key1);
          ASSERT_EQ(sobol_owen_1d(pixel, sample, dimension, seed),
                    bits_to_unit_float(nested_uniform_scramble(sobol_dimension0(index1), pcg_hash(key1 ^ 0x3u))));
        }
}

TEST(SamplingSobolOwen, EveryPowerOfTwoOfSamplesIsANet) {
  // For N = 2^m samples of one pixel, each elementary box 2^-a x 2^-(m-a) holds exactly one
  // point, for every a: stratified in all aspect ratios, including the N^(1/2) x N^(1/2) grid.
  for (uint32_t pixel : {0u, 1u, 12345u, 999999u})
    for (uint32_t dimension : {0u, 1u, 5u})
      for (int m = 0; m <= 10; ++m) {
        const uint32_t n = 1u << m;
        std::vector<Vec2> points(n);
        for (uint32_t s = 0; s < n; ++s) {
          points[s] = sobol_owen_2d(pixel, s, dimension, 3);
          ASSERT_EQ(points[s], sobol_owen_2d(pixel, s, dimension, 3));  // deterministic
          ASSERT_TRUE(points[s].x >= 0.0f && points[s].x < 1.0f && points[s].y >= 0.0f && points[s].y < 1.0f);
        }
        for (int a = 0; a <= m; ++a) {
          std::vector<int> boxes(n, 0);
          for (const Vec2& p : points) {
            const uint32_t bx = uint32_t(p.x * float(1u << a)), by = uint32_t(p.y * float(1u << (m - a)));
            ++boxes[(bx << (m - a)) | by];
          }
          for (int c : boxes) ASSERT_EQ(c, 1) << "pixel " << pixel << " m " << m << " a " << a;
        }
      }
  // The 1D pattern is stratified the same way: 2^m samples, one per interval of 2^-m.
  for (int m = 0; m <= 10; ++m) {
    std::vector<int> intervals(1u << m, 0);
    for (uint32_t s = 0; s < (1u << m); ++s) ++intervals[int(sobol_owen_1d(77, s, 2, 3) * float(1u << m))];
    for (int c : intervals) ASSERT_EQ(c, 1) << "1D, m " << m;
  }
}

TEST(SamplingSobolOwen, UniformAndDecorrelatedAcrossPixelsAndDimensions) {
  // Owen scrambling makes each point uniform on its own: the same sample index over many pixels
  // is uniform, and two dimensions of one sample are independent.
  constexpr int kGrid = 16, kN = 100000;
  std::vector<double> same_index(kGrid * kGrid, 0.0), across_dims(kGrid * kGrid, 0.0),
      probabilities(kGrid * kGrid, 1.0 / (kGrid * kGrid));
  for (uint32_t pixel = 0; pixel < kN; ++pixel) {
    const Vec2 a = sobol_owen_2d(pixel, 3, 0, 1);
    same_index[int(a.x * kGrid) * kGrid + int(a.y * kGrid)] += 1.0;
    const Vec2 b = sobol_owen_2d(pixel, 3, 1, 1);
    across_dims[int(a.x * kGrid) * kGrid + int(b.x * kGrid)] += 1.0;
  }
  expect_fits(same_index, probabilities, kN, "sample 3 over pixels");
  expect_fits(across_dims, probabilities, kN, "dimension 0 against dimension 1");
}

TEST(SamplingSobolOwen, IntegratesBetterThanIndependentRandom) {
  // Mean squared error of the per-pixel estimate of two integrals with known values, against the
  // same estimate with independent uniform numbers: a stratified unbiased pattern has lower
  // variance (Owen: O(N^-3) for smooth integrands, O(N^-3/2) for an edge, against O(N^-1)).
  const auto smooth = [](Vec2 p) { return std::exp(-double(p.x)) * std::sin(3.0 * p.y) + double(p.x) * p.y; };
  const double smooth_exact = (1.0 - std::exp(-1.0)) * (1.0 - std::cos(3.0)) / 3.0 + 0.25;
  // An edge through the pixel, like a silhouette: the area below the line y = 0.3 + 0.4 x.
  const auto edge = [](Vec2 p) { return p.y < 0.3 + 0.4 * p.x ? 1.0 : 0.0; };
  const double edge_exact = 0.5;
  constexpr int kPixels = 4000, kSamples = 64;
  for (auto [f, exact, name] : {std::tuple{std::function<double(Vec2)>(smooth), smooth_exact, "smooth"},
                                std::tuple{std::function<double(Vec2)>(edge), edge_exact, "edge"}}) {
    double mse_sobol = 0.0, mse_random = 0.0;
    for (uint32_t pixel = 0; pixel < kPixels; ++pixel) {
      double sum_sobol = 0.0, sum_random = 0.0;
      for (uint32_t s = 0; s < kSamples; ++s) {
        sum_sobol += f(sobol_owen_2d(pixel, s, 0, 0));
        sum_random += f(Vec2(random_float(pixel, s, 0, 0), random_float(pixel, s, 1, 0)));
      }
      mse_sobol += std::pow(sum_sobol / kSamples - exact, 2);
      mse_random += std::pow(sum_random / kSamples - exact, 2);
    }
    // With 4000 pixels each MSE is known to a few per cent, so "lower" is decided by far.
    EXPECT_LT(mse_sobol, mse_random) << name;
    std::printf("%s: MSE random / Sobol-Owen = %.1f at %d spp\n", name, mse_random / mse_sobol, kSamples);
  }
}

TEST(SamplingWarp, UniformDiskChiSquare) {
  // Polar bins: P(r in [r0, r1], phi in [p0, p1]) = (r1^2 - r0^2) (p1 - p0) / (2 pi).
  constexpr int kR = 16, kPhi = 16, kN = 200000;
  std::vector<double> counts(kR * kPhi, 0.0), probabilities(kR * kPhi);
  for (int r = 0; r < kR; ++r)
    for (int p = 0; p < kPhi; ++p)
      probabilities[r * kPhi + p] = (std::pow((r + 1.0) / kR, 2) - std::pow(double(r) / kR, 2)) / kPhi;
  for (int i = 0; i < kN; ++i) {
    const Vec2 d = sample_uniform_disk_concentric(rand2(i, 1));
    const double radius = std::hypot(double(d.x), double(d.y));
    ASSERT_LE(radius, 1.0 + 1e-6);
    double phi = std::atan2(double(d.y), double(d.x));
    if (phi < 0.0) phi += 2.0 * kPiD;
    counts[std::min(kR - 1, int(radius * kR)) * kPhi + std::min(kPhi - 1, int(phi / (2 * kPiD) * kPhi))] += 1.0;
  }
  expect_fits(counts, probabilities, kN, "concentric disk");
  EXPECT_FLOAT_EQ(uniform_disk_pdf() * kPi, 1.0f);
}

TEST(SamplingWarp, CosineHemisphereChiSquare) {
  // Density cos(theta) / pi: P(theta' < theta) = sin^2(theta).
  expect_directions_fit(
      sample_cosine_hemisphere, kPiD / 2, [](double t) { return std::pow(std::sin(t), 2); }, "cosine hemisphere");
  EXPECT_FLOAT_EQ(cosine_hemisphere_pdf(0.5f), 0.5f / kPi);
}

TEST(SamplingWarp, UniformSphereChiSquare) {
  // Density 1 / (4 pi): P(theta' < theta) = (1 - cos theta) / 2.
  expect_directions_fit(
      sample_uniform_sphere, kPiD, [](double t) { return (1.0 - std::cos(t)) / 2.0; }, "uniform sphere");
}

TEST(SamplingWarp, UniformConeChiSquare) {
  for (double theta_max : {0.05, 0.6, kPiD / 2, 2.5}) {
    const float one_minus_cos = float(2.0 * std::pow(std::sin(theta_max / 2.0), 2));
    expect_directions_fit([&](Vec2 u) { return sample_uniform_cone(u, one_minus_cos); }, theta_max,
                          [&](double t) { return (1.0 - std::cos(t)) / (1.0 - std::cos(theta_max)); }, "uniform cone");
    // The density integrates to one over the cap: pdf * solid angle = 1.
    EXPECT_NEAR(uniform_cone_pdf(one_minus_cos) * 2.0 * kPiD * (1.0 - std::cos(theta_max)), 1.0, 1e-5);
  }
  // A cap far too small for 1 - cos in float still gives unit directions inside it.
  const float tiny = 1e-12f;
  for (int i = 0; i < 100; ++i) {
    const Vec3 d = sample_uniform_cone(rand2(i, 5), tiny);
    EXPECT_NEAR(glm::length(d), 1.0f, 1e-6f);
    EXPECT_LE(std::hypot(d.x, d.y), std::sqrt(2.0f * tiny) * 1.0001f);
  }
}

TEST(SamplingWarp, UniformTriangleChiSquare) {
  // A grid over the unit square holding the triangle (0,0), (1,0), (0,1), mapped from the
  // barycentrics: cells below the diagonal have probability 2 / n^2, cells on it half that, cells
  // above it zero.
  constexpr int kGrid = 16, kN = 200000;
  std::vector<double> counts(kGrid * kGrid, 0.0), probabilities(kGrid * kGrid);
  for (int i = 0; i < kGrid; ++i)
    for (int j = 0; j < kGrid; ++j)
      probabilities[i * kGrid + j] = i + j < kGrid - 1    ? 2.0 / (kGrid * kGrid)
                                     : i + j == kGrid - 1 ? 1.0 / (kGrid * kGrid)
                                                          : 0.0;
  for (int n = 0; n < kN; ++n) {
    const Vec2 b = sample_uniform_triangle(rand2(n, 4));
    ASSERT_TRUE(b.x >= 0.0f && b.y >= 0.0f && b.x + b.y <= 1.0f + 1e-6f);
    // p = (1 - b1 - b2) p0 + b1 p1 + b2 p2 with p0 = (0,0), p1 = (1,0), p2 = (0,1) is (b1, b2).
    counts[std::min(kGrid - 1, int(b.x * kGrid)) * kGrid + std::min(kGrid - 1, int(b.y * kGrid))] += 1.0;
  }
  expect_fits(counts, probabilities, kN, "uniform triangle");
}

TEST(SamplingWarp, FrameIsOrthonormalAndRightHanded) {
  for (int i = 0; i < 1000; ++i) {
    const Vec3 n = sample_uniform_sphere(rand2(i, 8));
    const Frame f = Frame::from_normal(n);
    EXPECT_NEAR(glm::dot(f.t, f.b), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::dot(f.t, f.n), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::length(f.t), 1.0f, 1e-5f);
    EXPECT_NEAR(glm::length(f.b), 1.0f, 1e-5f);
    EXPECT_NEAR(glm::length(glm::cross(f.t, f.b) - n), 0.0f, 1e-5f);
    const Vec3 v = sample_uniform_sphere(rand2(i, 9));
    EXPECT_NEAR(glm::length(f.to_world(f.to_local(v)) - v), 0.0f, 1e-5f);
  }
}
