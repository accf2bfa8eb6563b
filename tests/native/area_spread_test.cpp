// An area light's spread (lights/area_spread.h) against closed forms: the slats keep the light's
// power; under a soft box wider than its beam the irradiance is pi L whatever the spread and the
// height (the integral of (tan h - x) x / (1 + x^2)^2 from 0 to tan h is (tan h - h) / 2, which
// the normalisation 1 / (tan h - h) cancels), as under an infinite plain light; elsewhere both
// estimators converge to a quadrature over the light; sample() and evaluate() agree on radiance
// and density (multiple importance sampling needs it); Cycles 3.x's form of f is the same function.
#include "lights/light.h"

#include "light_estimates.h"

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <stdexcept>

using namespace toyrt;
using namespace toyrt::testing;

namespace {

constexpr double kDegree = kPiD / 180.0;

// A light of shape `shape`, sx x sy, at height h above the origin, facing down, 100 W, white.
AreaLight soft_box(AreaShape shape, float sx, float sy, float h, double spread) {
  return AreaLight::make(shape, sx, sy, glm::translate(Mat4(1.0f), Vec3(0.0f, 0.0f, h)), 100.0f, Vec3(1.0f),
                         float(spread));
}

// Irradiance at p (facing up) from a rectangle light centred over the origin, by the midpoint rule
// over the light: L f(theta) cos_p cos_l / d^2 dA, in double.
double quadrature_irradiance(const AreaLight& light, double sx, double sy, double h, const Vec3& p, int n) {
  double sum = 0.0;
  const double da = sx / n * sy / n;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double x = -sx / 2 + (i + 0.5) * sx / n - p.x, y = -sy / 2 + (j + 0.5) * sy / n - p.y, z = h - p.z;
      const double d2 = x * x + y * y + z * z, cos = z / std::sqrt(d2);
      sum += light.spread.at_tan(float(std::sqrt(x * x + y * y) / z)) * cos * cos / d2 * da;
    }
  return double(light.radiance.x) * sum;
}

}  // namespace

TEST(AreaSpread, SlatsKeepTheLightsPower) {
  // The integral of f(theta) cos(theta) over the hemisphere is pi, as for f = 1.
  for (double degrees : {1.0, 5.0, 10.0, 30.0, 90.0, 150.0, 179.0}) {
    const AreaSpread s = AreaSpread::make(float(degrees * kDegree));
    const double h = 0.5 * degrees * kDegree;
    const int n = 200000;
    double integral = 0.0;
    for (int i = 0; i < n; ++i) {  // f is 0 beyond h: integrate over [0, h] only
      const double theta = (i + 0.5) * h / n;
      integral += s.at_tan(float(std::tan(theta))) * std::cos(theta) * std::sin(theta) * 2.0 * kPiD * h / n;
    }
    EXPECT_NEAR(integral / kPiD, 1.0, 2e-4) << degrees << " degrees";
    EXPECT_EQ(s.at_tan(float(std::tan(h * 1.001))), 0.0f) << "beyond the beam";
  }
  EXPECT_FALSE(AreaSpread::make(float(kPiD)).active);
  EXPECT_EQ(AreaSpread::make(float(kPiD)).at_tan(3.0f), 1.0f);
}

TEST(AreaSpread, Cycles3xFormIsTheSameFunction) {
  // Cycles 3.x: a = (pi - spread) / 2, f = max(1 - tan(a) tan(theta), 0) * 2 / (2 + (2 a - pi) tan(a)).
  for (double degrees : {2.0, 20.0, 60.0, 120.0, 170.0}) {
    const double a = 0.5 * (kPiD - degrees * kDegree), norm3 = 2.0 / (2.0 + (2.0 * a - kPiD) * std::tan(a));
    const AreaSpread s = AreaSpread::make(float(degrees * kDegree));
    for (double theta_deg : {0.0, 0.2, 0.45, 0.7, 0.95}) {
      const double theta = theta_deg * 0.5 * degrees * kDegree;
      const double cycles3 = std::max(1.0 - std::tan(a) * std::tan(theta), 0.0) * norm3;
      EXPECT_NEAR(s.at_tan(float(std::tan(theta))), cycles3, 2e-4 * cycles3 + 1e-6) << degrees << " deg at " << theta;
    }
  }
}

TEST(AreaSpread, UnderASoftBoxWiderThanItsBeamIrradianceIsPiL) {
  for (AreaSampling sampling : {AreaSampling::Area, AreaSampling::SolidAngle})
    for (double degrees : {1.0, 30.0, 90.0})
      for (AreaShape shape : {AreaShape::Square, AreaShape::Disk}) {
        if (shape == AreaShape::Disk && degrees < 10.0) continue;  // disks are not clamped: too few hits
        const float h = 0.8f;
        const Light light = soft_box(shape, 3.0f, 3.0f, h, degrees * kDegree);  // reach at 90 deg: 0.8 m
        const double pi_l = kPiD * std::get<AreaLight>(light).radiance.x;
        const Estimate e = monte_carlo(200000, [&](uint32_t i) {
          return irradiance_sample(light, Vec3(0.0f), Vec3(0, 0, 1), rand2(i, 9), sampling);
        });
        expect_converges(e, pi_l, degrees < 10.0 ? "1 degree" : shape == AreaShape::Disk ? "disk" : "square");
      }
}

TEST(AreaSpread, BothEstimatorsConvergeWhereTheLightsEdgeCutsTheBeam) {
  const float sx = 1.2f, sy = 0.7f, h = 0.6f;
  const AreaLight box = soft_box(AreaShape::Rectangle, sx, sy, h, 40.0 * kDegree);
  const Light light = box;
  // Under the light near an edge, beside the light (lit only through the slats' angle), and too
  // far beside it for the beam to reach (0 exactly).
  for (Vec3 p : {Vec3(0.5f, 0.2f, 0.0f), Vec3(0.75f, 0.0f, 0.0f), Vec3(0.0f, 0.55f, 0.1f), Vec3(1.2f, 0.0f, 0.0f)}) {
    const double exact = quadrature_irradiance(box, sx, sy, h, p, 1500);
    for (AreaSampling sampling : {AreaSampling::Area, AreaSampling::SolidAngle}) {
      const Estimate e = monte_carlo(
          100000, [&](uint32_t i) { return irradiance_sample(light, p, Vec3(0, 0, 1), rand2(i, 3), sampling); });
      if (p.x > 1.0f) {
        EXPECT_EQ(exact, 0.0);
        EXPECT_EQ(e.mean, 0.0) << "beyond the beam's reach";
      } else {
        // The midpoint rule's error at f's kink (about 1e-4 relative) on top of the Monte Carlo error.
        EXPECT_NEAR(e.mean, exact, 4.0 * e.standard_error + 3e-4 * exact) << "at " << p.x << ", " << p.y;
      }
    }
  }
}

TEST(AreaSpread, EvaluateGivesTheRadianceAndDensityOfEachSample) {
  for (AreaShape shape : {AreaShape::Rectangle, AreaShape::Ellipse})
    for (AreaSampling sampling : {AreaSampling::Area, AreaSampling::SolidAngle}) {
      const Light light = soft_box(shape, 1.5f, 0.8f, 0.9f, 50.0 * kDegree);
      const LightContext ctx{sampling};
      int checked = 0;
      for (uint32_t i = 0; i < 4000; ++i) {
        const Vec3 p(2.0f * rand2(i, 1).x - 1.0f, 2.0f * rand2(i, 1).y - 1.0f, 0.0f);
        const LightSample s = sample_light(light, p, rand2(i, 2), sampling);
        if (!s.valid()) continue;
        const LightEval e = evaluate_light(light, p, s.wi, ctx);
        ASSERT_TRUE(e.hit());
        EXPECT_NEAR(e.radiance.x, s.radiance.x, 1e-3f * s.radiance.x);
        EXPECT_NEAR(e.pdf, s.pdf, 1e-3f * s.pdf);
        EXPECT_NEAR(e.distance, s.distance, 1e-4f);
        ++checked;
      }
      EXPECT_GT(checked, 500);
    }
}

TEST(AreaSpread, ImportanceIsPositiveWhereverTheBeamArrives) {
  const Light light = soft_box(AreaShape::Rectangle, 1.0f, 0.6f, 0.5f, 30.0 * kDegree);
  int lit = 0;
  for (uint32_t i = 0; i < 2000; ++i) {
    const Vec3 p(3.0f * rand2(i, 4).x - 1.5f, 3.0f * rand2(i, 4).y - 1.5f, 0.0f);
    bool arrives = false;
    for (uint32_t k = 0; k < 64 && !arrives; ++k)
      arrives = sample_light(light, p, rand2(k, 6), AreaSampling::SolidAngle).valid();
    if (!arrives) continue;
    ++lit;
    EXPECT_GT(importance(std::get<AreaLight>(light), p, Vec3(0, 0, 1)), 0.0f);
  }
  EXPECT_GT(lit, 100);
  // Far beside the light, outside every angle the slats pass: no importance.
  EXPECT_EQ(importance(std::get<AreaLight>(light), Vec3(5.0f, 0.0f, 0.0f), Vec3(0, 0, 1)), 0.0f);
}

TEST(AreaSpread, RejectsASpreadThatIsNotAPositiveAngle) {
  for (float bad : {0.0f, -0.1f, NAN, INFINITY})
    EXPECT_THROW(soft_box(AreaShape::Square, 1.0f, 1.0f, 1.0f, bad), std::invalid_argument) << bad;
  EXPECT_NO_THROW(soft_box(AreaShape::Square, 1.0f, 1.0f, 1.0f, 4.0));  // beyond 180 degrees: no slats
}
