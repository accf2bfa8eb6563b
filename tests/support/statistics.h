// Quantiles for statistical tests of samplers, computed rather than tabulated.
#pragma once

#include <cmath>
#include <vector>

namespace toyrt::testing {

// Standard normal upper quantile: the z with P(Z > z) = alpha, by bisection on erfc (exact to
// double precision, no tabulated constant).
inline double normal_upper_quantile(double alpha) {
  double lo = -10.0, hi = 10.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(mid / std::sqrt(2.0)) > alpha ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// Upper alpha quantile of the chi-square distribution with k degrees of freedom, by the
// Wilson-Hilferty approximation ((X/k)^(1/3) is nearly normal with mean 1 - 2/(9k) and variance
// 2/(9k)); its relative error is below 1 % for k >= 10 at these tail probabilities.
inline double chi_square_quantile(int k, double alpha) {
  const double v = 2.0 / (9.0 * k);
  const double c = 1.0 - v + normal_upper_quantile(alpha) * std::sqrt(v);
  return k * c * c * c;
}

// Pearson's statistic of observed `counts` against `expected` counts per bin, with the bins
// expecting fewer than 5 pooled into one (the test's usual validity rule): the statistic, the
// number of bins it sums (degrees of freedom + 1) and what the pooled bins saw and expected
// (the pool joins the sum only when it expects 5 or more).
struct PooledChiSquare {
  double chi2 = 0.0;
  int bins = 0;
  double pooled_count = 0.0, pooled_expected = 0.0;
};

inline PooledChiSquare pooled_chi_square(const std::vector<double>& counts, const std::vector<double>& expected) {
  PooledChiSquare r;
  for (size_t c = 0; c < counts.size(); ++c) {
    if (expected[c] < 5.0) {
      r.pooled_count += counts[c];
      r.pooled_expected += expected[c];
      continue;
    }
    r.chi2 += (counts[c] - expected[c]) * (counts[c] - expected[c]) / expected[c];
    ++r.bins;
  }
  if (r.pooled_expected >= 5.0) {
    r.chi2 += (r.pooled_count - r.pooled_expected) * (r.pooled_count - r.pooled_expected) / r.pooled_expected;
    ++r.bins;
  }
  return r;
}

}  // namespace toyrt::testing
