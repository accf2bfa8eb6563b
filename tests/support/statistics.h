// Quantiles for statistical tests of samplers, computed rather than tabulated.
#pragma once

#include <cmath>

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

}  // namespace toyrt::testing
