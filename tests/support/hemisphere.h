// Numerical integration over the upper hemisphere (z > 0) for the BSDF tests' closed forms.
#pragma once

#include "core/math.h"

#include <cmath>

namespace toyrt::testing {

inline Vec3 direction(double theta, double phi) {
  return Vec3(float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)));
}

// The integral of g(w) over the upper hemisphere by the midpoint rule in (theta, phi).
template <class G>
double hemisphere_integral(G g, int n_theta = 512, int n_phi = 256) {
  double sum = 0.0;
  const double dt = 0.5 * M_PI / n_theta, dp = 2.0 * M_PI / n_phi;
  for (int i = 0; i < n_theta; ++i) {
    const double theta = (i + 0.5) * dt;
    for (int j = 0; j < n_phi; ++j) sum += g(direction(theta, (j + 0.5) * dp)) * std::sin(theta) * dt * dp;
  }
  return sum;
}

}  // namespace toyrt::testing
