// Monte Carlo checks of light samplers shared by the light tests: an estimator's mean and
// standard error, agreement with a closed form within 4 standard errors, and the one-sample
// direct irradiance a light gives a receiver.
#pragma once

#include "lights/light.h"
#include "sampling/rng.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

namespace toyrt::testing {

constexpr double kPiD = 3.14159265358979323846;

inline Vec2 rand2(uint32_t i, uint32_t seed) { return {random_float(i, 0, 0, seed), random_float(i, 0, 1, seed)}; }

// Mean and standard error of n samples of an estimator.
struct Estimate {
  double mean = 0.0, standard_error = 0.0;
};
inline Estimate monte_carlo(int n, const std::function<double(uint32_t)>& sample) {
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    const double x = sample(uint32_t(i));
    sum += x;
    sum2 += x * x;
  }
  const double mean = sum / n, variance = std::max(0.0, sum2 / n - mean * mean);
  return {mean, std::sqrt(variance / n)};
}

// The estimate agrees with the exact value within 4 standard errors (a 6e-5 chance of failing a
// correct estimator, and the inputs are fixed), plus float rounding.
inline void expect_converges(const Estimate& e, double exact, const char* what) {
  EXPECT_NEAR(e.mean, exact, 4.0 * e.standard_error + 1e-5 * std::fabs(exact))
      << what << ": standard error " << e.standard_error;
}

// Direct irradiance at p with normal n (red channel) from one light sample; `sampling` is the
// render's estimator for rectangular area lights.
inline double irradiance_sample(const Light& light, const Vec3& p, const Vec3& n, const Vec2& u,
                                AreaSampling sampling = AreaSampling::SolidAngle) {
  const LightSample s = sample_light(light, p, u, sampling);
  if (!s.valid()) return 0.0;
  return double(s.radiance.x) * std::max(0.0f, glm::dot(n, s.wi)) / s.pdf;
}

}  // namespace toyrt::testing
