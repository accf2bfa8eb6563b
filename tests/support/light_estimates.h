// Monte Carlo checks of light samplers shared by the light tests: an estimator's mean and
// standard error, agreement with a closed form within 4 standard errors, and the one-sample
// direct irradiance a light gives a receiver; a mixed set of every lamp type for the light
// structures' tests.
#pragma once

#include "lights/light.h"
#include "sampling/rng.h"

#include <glm/gtc/matrix_transform.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

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

// `count` lights over [-10, 10]^2 at heights 0.5 to 3.5 (and a fifth below the floor, -3.5 to
// -0.5, which a receiver facing up cannot see): point lights of every radius, spots, area lights
// facing down (or up for a few), and two suns. Powers vary over two decades.
inline std::vector<Light> mixed_lights(uint32_t count, uint32_t seed) {
  std::vector<Light> lights;
  for (uint32_t i = 0; i < count; ++i) {
    const auto r = [&](uint32_t d) { return random_float(i, 0, d, seed); };
    const float z = (i % 5 == 4 ? -1.0f : 1.0f) * (0.5f + 3.0f * r(2));
    const Vec3 pos(20.0f * r(0) - 10.0f, 20.0f * r(1) - 10.0f, z);
    const float power = 1.0f + 99.0f * r(3) * r(3);
    const Mat4 at = glm::translate(Mat4(1.0f), pos);
    switch (i % 4) {
      case 0:
        lights.emplace_back(PointLight::make(pos, power, Vec3(1.0f)));
        break;
      case 1:
        lights.emplace_back(PointLight::make(pos, power, Vec3(1.0f, 0.5f, 0.2f), 0.3f * r(4)));
        break;
      case 2: {
        SpotLight::Settings s;
        s.matrix = glm::rotate(at, 3.0f * r(4), glm::normalize(Vec3(r(5), r(6), 0.1f)));
        s.power = power;
        lights.emplace_back(SpotLight::make(s));
        break;
      }
      default: {
        // Facing down, or up (then it lights nothing above the floor) for one in three.
        const Mat4 m = i % 3 == 0 ? glm::rotate(at, kPi, Vec3(1, 0, 0)) : at;
        lights.emplace_back(AreaLight::make(AreaShape::Rectangle, 0.2f + r(4), 0.2f + r(5), m, power, Vec3(1.0f)));
      }
    }
  }
  for (float tilt : {0.3f, 1.2f}) {
    SunLight::Settings s;
    s.matrix = glm::rotate(Mat4(1.0f), tilt, Vec3(0, 1, 0));
    s.strength = 0.5f;
    lights.emplace_back(SunLight::make(s));
  }
  return lights;
}

}  // namespace toyrt::testing
