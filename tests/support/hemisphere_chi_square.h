// A reflection sampler's histogram against its pdf (Pearson's chi-square, as Mitsuba's test suite
// checks its BSDFs): bins in (theta, phi) over the upper hemisphere, whose expected masses come
// from quadrature of the pdf, and one bin for the draws that give no direction, expecting what the
// pdf leaves of 1 (a GGX sampler's reflections below the horizon).
#pragma once

#include "core/math.h"
#include "hemisphere.h"
#include "sampling/warp.h"  // Vec2
#include "statistics.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace toyrt::testing {

// sample(u): a local direction (z up), or a zero vector for no direction; pdf(w): its density per
// solid angle. Returns the pooled statistic; compare chi2 with chi_square_quantile(bins - 1, ...).
template <class Sample, class Pdf>
PooledChiSquare hemisphere_chi_square(Sample&& sample, Pdf&& pdf, int samples = 400000, uint32_t seed = 7) {
  constexpr int kTheta = 24, kPhi = 48, kSub = 6;
  std::vector<double> expected(kTheta * kPhi + 1, 0.0);
  const double dt = 0.5 * M_PI / (kTheta * kSub), dp = 2.0 * M_PI / (kPhi * kSub);
  double above = 0.0;
  for (int i = 0; i < kTheta * kSub; ++i) {
    const double theta = (i + 0.5) * dt;
    for (int j = 0; j < kPhi * kSub; ++j) {
      const double p = double(pdf(direction(theta, (j + 0.5) * dp))) * std::sin(theta) * dt * dp;
      expected[size_t((i / kSub) * kPhi + j / kSub)] += p * samples;
      above += p;
    }
  }
  expected.back() = std::max(0.0, 1.0 - above) * samples;
  std::vector<double> counts(expected.size(), 0.0);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  for (int k = 0; k < samples; ++k) {
    const float u0 = uniform(rng), u1 = uniform(rng);
    const Vec3 w = sample(Vec2(u0, u1));
    if (!(w.z > 0.0f)) {
      counts.back() += 1.0;
      continue;
    }
    const double theta = std::acos(std::clamp(double(w.z), -1.0, 1.0));
    double phi = std::atan2(double(w.y), double(w.x));
    if (phi < 0.0) phi += 2.0 * M_PI;
    const int i = std::min(kTheta - 1, int(theta / (0.5 * M_PI) * kTheta));
    const int j = std::min(kPhi - 1, int(phi / (2.0 * M_PI) * kPhi));
    counts[size_t(i * kPhi + j)] += 1.0;
  }
  return pooled_chi_square(counts, expected);
}

}  // namespace toyrt::testing
