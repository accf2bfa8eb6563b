// Lights against closed forms in Blender's units: a point light's I cos / r^2, a sphere's
// irradiance (equal to the point's while it is above the horizon), a parallel rectangle's and a
// disk's irradiance, approached by every estimator within its own standard error; the
// spherical-rectangle sampler's density (constant 1 / Omega, chi-square per sub-rectangle); the
// Cycles measurements of BLENDER_UNITS.md; and light selection.
#include "lights/light.h"
#include "lights/light_selector.h"
#include "lights/spherical_rectangle.h"
#include "sampling/rng.h"

#include "light_estimates.h"
#include "statistics.h"

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <functional>
#include <stdexcept>
#include <vector>

using namespace toyrt;
using toyrt::testing::chi_square_quantile;
using namespace toyrt::testing;

namespace {

// Point at height h under a corner of a parallel a x b rectangle of radiance L, receiver facing it:
// E = pi L F with the configuration factor of Howell's catalogue (differential element to a
// parallel rectangle, normal through a corner), A = a / h, B = b / h:
//   F = 1/(2 pi) [A/sqrt(1+A^2) atan(B/sqrt(1+A^2)) + B/sqrt(1+B^2) atan(A/sqrt(1+B^2))].
// The limit a, b -> inf gives F = 1/4, a quarter of the infinite plane, as it must.
double corner_irradiance_over_radiance(double a, double b, double h) {
  const double A = a / h, B = b / h, sa = std::sqrt(1.0 + A * A), sb = std::sqrt(1.0 + B * B);
  return 0.5 * (A / sa * std::atan(B / sa) + B / sb * std::atan(A / sb));
}
// Solid angle of the same corner rectangle: atan(a b / (h sqrt(a^2 + b^2 + h^2))).
double corner_solid_angle(double a, double b, double h) {
  return std::atan(a * b / (h * std::sqrt(a * a + b * b + h * h)));
}
// Any rectangle [x0, x1] x [y0, y1] (relative to the foot of p) from corner rectangles by
// inclusion-exclusion, with the quantity extended oddly to negative coordinates.
double over_rectangle(double (*corner)(double, double, double), double x0, double x1, double y0, double y1, double h) {
  const auto g = [&](double x, double y) {
    return (x < 0 ? -1.0 : 1.0) * (y < 0 ? -1.0 : 1.0) * corner(std::fabs(x), std::fabs(y), h);
  };
  return g(x1, y1) - g(x0, y1) - g(x1, y0) + g(x0, y0);
}

// A light 1 m wide rectangle `sx` x `sy` at height h above the origin, facing down (-Z, Blender's
// default orientation), power P, white.
AreaLight ceiling_light(AreaShape shape, float sx, float sy, float h, float power) {
  return AreaLight::make(shape, sx, sy, glm::translate(Mat4(1.0f), Vec3(0.0f, 0.0f, h)), power, Vec3(1.0f));
}

}  // namespace

TEST(PointLight, IrradianceIsIntensityCosOverDistanceSquared) {
  const float power = 100.0f;
  const Vec3 colour(1.0f, 0.5f, 0.25f);
  const PointLight light = PointLight::make(Vec3(0.3f, -0.2f, 2.0f), power, colour);
  for (Vec3 p : {Vec3(0.3f, -0.2f, 1.0f), Vec3(1.0f, 1.0f, 0.0f), Vec3(-3.0f, 0.5f, -1.0f), Vec3(10.0f, 0.0f, 0.0f)})
    for (Vec3 n : {Vec3(0, 0, 1), glm::normalize(Vec3(1, 0, 1)), glm::normalize(Vec3(-0.2f, 0.7f, 0.3f))}) {
      const LightSample s = sample(light, p, Vec2(0.5f));
      ASSERT_TRUE(s.valid() && s.delta);
      const Vec3 to_light = Vec3(0.3f, -0.2f, 2.0f) - p;
      const float r2 = glm::dot(to_light, to_light);
      const float cos_theta = std::max(0.0f, glm::dot(n, to_light) / std::sqrt(r2));
      for (int c = 0; c < 3; ++c) {
        const float expected = power * colour[c] / (4.0f * float(kPiD)) * cos_theta / r2;
        EXPECT_NEAR(s.radiance[c] * std::max(0.0f, glm::dot(n, s.wi)) / s.pdf, expected, 1e-5f * expected + 1e-9f);
      }
      EXPECT_NEAR(s.distance, std::sqrt(r2), 1e-5f);
      EXPECT_FALSE(evaluate(light, p, s.wi).hit());  // a delta light cannot be hit
    }
}

TEST(PointLight, MatchesCyclesPixelOfBlenderUnits) {
  // BLENDER_UNITS.md (Cycles, Blender 3.4.1): 100 W point light 1 m above a white Lambert plane,
  // centre pixel 2.533 = (albedo / pi) E.
  const PointLight light = PointLight::make(Vec3(0, 0, 1), 100.0f, Vec3(1.0f));
  const double pixel = irradiance_sample(light, Vec3(0.0f), Vec3(0, 0, 1), Vec2(0.5f)) / kPiD;
  EXPECT_NEAR(pixel, 2.533, 0.0005 * 2.533);
}

TEST(PointLight, RejectsInvalidSettings) {
  EXPECT_THROW(PointLight::make(Vec3(0), -1.0f, Vec3(1)), std::invalid_argument);
  EXPECT_THROW(PointLight::make(Vec3(0), 1.0f, Vec3(1, -1, 1)), std::invalid_argument);
  EXPECT_THROW(PointLight::make(Vec3(0), 1.0f, Vec3(1), -0.1f), std::invalid_argument);
  EXPECT_THROW(PointLight::make(Vec3(NAN, 0, 0), 1.0f, Vec3(1)), std::invalid_argument);
  EXPECT_THROW(PointLight::make(Vec3(0), INFINITY, Vec3(1)), std::invalid_argument);
}

TEST(SphereLight, RadianceEmitsThePowerOfThePointLight) {
  // A Lambertian sphere emits pi L per unit area over 4 pi R^2: that must be P (per channel).
  const float power = 60.0f, radius = 0.2f;
  const Vec3 colour(0.8f, 0.4f, 1.0f);
  const PointLight light = PointLight::make(Vec3(0), power, colour, radius);
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(double(light.radiance[c]) * kPiD * 4.0 * kPiD * radius * radius, power * colour[c], 1e-4 * power);
}

TEST(SphereLight, IrradianceEqualsPointLightWhileAboveTheHorizon) {
  // A uniform sphere entirely above the receiver's tangent plane gives exactly I cos / d^2.
  const float power = 100.0f, radius = 0.3f;
  const Light light = PointLight::make(Vec3(0, 0, 1), power, Vec3(1.0f), radius, /*soft_falloff=*/false);
  const double intensity = power / (4.0 * kPiD);
  const double theta_max = std::asin(radius / 1.0);
  for (double tilt : {0.0, 0.5, 1.2}) {
    ASSERT_LT(tilt + theta_max, kPiD / 2);  // fully above the horizon
    const Vec3 n(float(std::sin(tilt)), 0.0f, float(std::cos(tilt)));
    const Estimate e =
        monte_carlo(100000, [&](uint32_t i) { return irradiance_sample(light, Vec3(0.0f), n, rand2(i, 1)); });
    expect_converges(e, intensity * std::cos(tilt), "sphere light");
  }
}

TEST(SphereLight, ConeSamplesLieOnTheVisibleCapWithConstantPdf) {
  const Vec3 centre(0.5f, -1.0f, 2.0f);
  const float radius = 0.4f;
  const PointLight light = PointLight::make(centre, 10.0f, Vec3(1.0f), radius, /*soft_falloff=*/false);
  for (Vec3 p : {Vec3(0.0f), Vec3(0.5f, -1.0f, 1.5f), Vec3(30.0f, 2.0f, -4.0f)}) {
    const double d = glm::length(DVec3(centre - p));
    const double expected_pdf = 1.0 / (2.0 * kPiD * (1.0 - std::sqrt(1.0 - radius * radius / (d * d))));
    for (uint32_t i = 0; i < 1000; ++i) {
      const LightSample s = sample(light, p, rand2(i, 2));
      ASSERT_TRUE(s.valid());
      EXPECT_NEAR(glm::length(s.point - centre), radius, 2e-5f * (1.0f + float(d)));
      // On the near side: the sphere's normal there faces p.
      EXPECT_GE(glm::dot(glm::normalize(s.point - centre), glm::normalize(p - s.point)), -2e-3f);
      EXPECT_NEAR(s.pdf, expected_pdf, 1e-4 * expected_pdf);
      EXPECT_NEAR(glm::length(s.wi), 1.0f, 1e-5f);
      // The MIS side sees the same density and distance along the same direction.
      const LightEval e = evaluate(light, p, s.wi);
      ASSERT_TRUE(e.hit());
      EXPECT_NEAR(e.pdf, s.pdf, 1e-4f * s.pdf);
      EXPECT_NEAR(e.distance, s.distance, 1e-3f * radius);
    }
  }
}

TEST(SphereLight, InsideTheSphereIrradianceIsPiL) {
  const Light light = PointLight::make(Vec3(0), 50.0f, Vec3(1.0f), 1.0f, /*soft_falloff=*/false);
  const double radiance = std::get<PointLight>(light).radiance.x;
  const Vec3 n = glm::normalize(Vec3(0.3f, -1.0f, 0.2f));
  const Estimate e = monte_carlo(
      100000, [&](uint32_t i) { return irradiance_sample(light, Vec3(0.2f, 0.1f, -0.3f), n, rand2(i, 3)); });
  expect_converges(e, kPiD * radiance, "inside a sphere light");
}

TEST(AreaLight, RadianceIsPowerOverFourArea) {
  const float power = 100.0f;
  const AreaLight square = ceiling_light(AreaShape::Square, 2.0f, 0.0f, 1.0f, power);
  EXPECT_FLOAT_EQ(square.radiance.x, power / (4.0f * 4.0f));
  const AreaLight disk = ceiling_light(AreaShape::Disk, 2.0f, 0.0f, 1.0f, power);
  EXPECT_FLOAT_EQ(disk.radiance.x, power / (4.0f * float(kPiD)));  // diameter 2: area pi
  const AreaLight ellipse = ceiling_light(AreaShape::Ellipse, 2.0f, 0.5f, 1.0f, power);
  EXPECT_FLOAT_EQ(ellipse.radiance.x, power / (4.0f * float(kPiD) * 0.25f));
  // The object's scale scales the light (Cycles), at constant power.
  const Mat4 scaled = glm::scale(glm::translate(Mat4(1.0f), Vec3(0, 0, 1)), Vec3(2.0f, 3.0f, 1.0f));
  const AreaLight rect = AreaLight::make(AreaShape::Rectangle, 1.0f, 0.5f, scaled, power, Vec3(1.0f, 0.5f, 0.0f));
  EXPECT_FLOAT_EQ(rect.area, 2.0f * 1.5f);
  EXPECT_FLOAT_EQ(rect.radiance.y, power * 0.5f / (4.0f * 3.0f));
  EXPECT_EQ(rect.radiance.z, 0.0f);
}

TEST(AreaLight, SmallLightsMatchCyclesPixelsOfBlenderUnits) {
  // BLENDER_UNITS.md (Cycles, Blender 3.4.1): 100 W, 1 m above a white Lambert plane, centre
  // pixel (albedo / pi) E: 5 cm square 7.950, 5 cm disk 7.953.
  for (auto [shape, measured] : {std::pair{AreaShape::Square, 7.950}, std::pair{AreaShape::Disk, 7.953}})
    for (AreaSampling sampling : {AreaSampling::Area, AreaSampling::SolidAngle}) {
      const Light light = ceiling_light(shape, 0.05f, 0.0f, 1.0f, 100.0f);
      const Estimate e = monte_carlo(20000, [&](uint32_t i) {
        return irradiance_sample(light, Vec3(0.0f), Vec3(0, 0, 1), rand2(i, 4), sampling);
      });
      EXPECT_NEAR(e.mean / kPiD, measured, 0.001 * measured);
    }
}

TEST(AreaLight, BothEstimatorsConvergeToTheRectangleIrradiance) {
  const float power = 80.0f, h = 0.7f, sx = 1.6f, sy = 0.9f;
  for (AreaSampling sampling : {AreaSampling::Area, AreaSampling::SolidAngle}) {
    const Light light = ceiling_light(AreaShape::Rectangle, sx, sy, h, power);
    const double radiance = power / (4.0 * sx * sy);
    // Under the centre (four equal corner rectangles), and off-centre, partly outside the light.
    for (Vec3 p : {Vec3(0.0f), Vec3(0.5f, -0.3f, 0.0f), Vec3(1.2f, 0.8f, 0.2f)}) {
      const double height = h - p.z;
      const double exact = radiance * over_rectangle(corner_irradiance_over_radiance, -sx / 2 - p.x, sx / 2 - p.x,
                                                     -sy / 2 - p.y, sy / 2 - p.y, height);
      const Estimate e = monte_carlo(
          100000, [&](uint32_t i) { return irradiance_sample(light, p, Vec3(0, 0, 1), rand2(i, 5), sampling); });
      expect_converges(e, exact, sampling == AreaSampling::Area ? "area sampling" : "solid-angle sampling");
    }
  }
  // Under the centre the sum of corners is 4 times one corner, as the brief's formula has it.
  EXPECT_NEAR(over_rectangle(corner_irradiance_over_radiance, -0.8, 0.8, -0.45, 0.45, 0.7),
              4.0 * corner_irradiance_over_radiance(0.8, 0.45, 0.7), 1e-12);
}

TEST(AreaLight, SolidAngleSamplesLieOnTheRectangleWithPdfOneOverSolidAngle) {
  // A tilted, rotated rectangle seen from several points in front of it.
  Mat4 m = glm::translate(Mat4(1.0f), Vec3(0.2f, 0.5f, 2.0f));
  m = glm::rotate(m, 0.6f, glm::normalize(Vec3(1.0f, 0.4f, 0.2f)));
  const AreaLight light = AreaLight::make(AreaShape::Rectangle, 1.5f, 0.8f, m, 10.0f, Vec3(1.0f));
  const Vec3 centre = light.center, ux = glm::normalize(light.edge_x), uy = glm::normalize(light.edge_y);
  int points = 0;
  for (uint32_t j = 0; j < 20; ++j) {
    const Vec3 p = centre + 3.0f * (Vec3(rand2(j, 6), random_float(j, 0, 2, 6)) - Vec3(0.5f));
    const double height = glm::dot(p - centre, light.normal);
    if (height <= 0.05) continue;
    ++points;
    // Omega from the corner formula, in the rectangle's frame.
    const double px = glm::dot(p - centre, ux), py = glm::dot(p - centre, uy);
    const double omega = over_rectangle(corner_solid_angle, -0.75 - px, 0.75 - px, -0.4 - py, 0.4 - py, height);
    for (uint32_t i = 0; i < 500; ++i) {
      const LightSample s = sample(light, p, rand2(i, 7), AreaSampling::SolidAngle);
      ASSERT_TRUE(s.valid());
      EXPECT_NEAR(s.pdf * omega, 1.0, 1e-4);
      const Vec3 local = s.point - centre;
      EXPECT_NEAR(glm::dot(local, light.normal), 0.0f, 1e-5f);
      EXPECT_LE(std::fabs(glm::dot(local, ux)), 0.75f + 1e-5f);
      EXPECT_LE(std::fabs(glm::dot(local, uy)), 0.4f + 1e-5f);
      EXPECT_NEAR(glm::length(p + s.distance * s.wi - s.point), 0.0f, 1e-5f);
      const LightEval e = evaluate(light, p, s.wi, AreaSampling::SolidAngle);
      ASSERT_TRUE(e.hit());
      EXPECT_NEAR(e.pdf, s.pdf, 1e-5f * s.pdf);
    }
  }
  EXPECT_GT(points, 5);
}

TEST(AreaLight, MeanInversePdfIsTheSolidAngle) {
  // E[1 / pdf] = integral of 1 over the directions the sampler covers = Omega, for any sampler.
  const float h = 0.5f;
  const Vec3 p(0.3f, 0.1f, 0.0f);
  const double omega = over_rectangle(corner_solid_angle, -1.0 - p.x, 1.0 - p.x, -0.5 - p.y, 0.5 - p.y, h);
  for (AreaSampling sampling : {AreaSampling::Area, AreaSampling::SolidAngle}) {
    const AreaLight light = ceiling_light(AreaShape::Rectangle, 2.0f, 1.0f, h, 1.0f);
    const Estimate e = monte_carlo(100000, [&](uint32_t i) {
      const LightSample s = sample(light, p, rand2(i, 8), sampling);
      return s.valid() ? 1.0 / s.pdf : 0.0;
    });
    expect_converges(e, omega, "mean of 1 / pdf");
  }
}

TEST(AreaLight, SolidAngleSamplerChiSquarePerSubRectangle) {
  // Each cell of an 8 x 8 grid on the light should receive its solid angle over Omega of the samples.
  constexpr int kGrid = 8, kN = 100000;
  const float sx = 2.0f, sy = 1.2f;
  const AreaLight light = ceiling_light(AreaShape::Rectangle, sx, sy, 1.0f, 1.0f);
  for (Vec3 p : {Vec3(0.0f, 0.0f, 0.8f), Vec3(0.9f, -0.5f, 0.95f), Vec3(2.0f, 1.2f, 0.2f)}) {
    const double height = 1.0 - p.z;
    std::vector<double> counts(kGrid * kGrid, 0.0), expected(kGrid * kGrid);
    double omega = 0.0;
    for (int i = 0; i < kGrid; ++i)
      for (int j = 0; j < kGrid; ++j) {
        const double x0 = -sx / 2.0 + sx * i / kGrid, y0 = -sy / 2.0 + sy * j / kGrid;
        expected[i * kGrid + j] = over_rectangle(corner_solid_angle, x0 - p.x, x0 + sx / kGrid - p.x, y0 - p.y,
                                                 y0 + sy / kGrid - p.y, height);
        omega += expected[i * kGrid + j];
      }
    for (int n = 0; n < kN; ++n) {
      const LightSample s = sample(light, p, rand2(n, 9), AreaSampling::SolidAngle);
      ASSERT_TRUE(s.valid());
      const int i = std::clamp(int((s.point.x + sx / 2) / sx * kGrid), 0, kGrid - 1);
      const int j = std::clamp(int((s.point.y + sy / 2) / sy * kGrid), 0, kGrid - 1);
      counts[i * kGrid + j] += 1.0;
    }
    // Cells expecting fewer than 5 samples (far corners seen from a close point) are pooled.
    double chi2 = 0.0, pooled_count = 0.0, pooled_expected = 0.0;
    int bins = 0;
    for (int c = 0; c < kGrid * kGrid; ++c) {
      const double e = expected[c] / omega * kN;
      if (e < 5.0) {
        pooled_count += counts[c];
        pooled_expected += e;
        continue;
      }
      chi2 += (counts[c] - e) * (counts[c] - e) / e;
      ++bins;
    }
    if (pooled_expected > 0.0) {
      chi2 += (pooled_count - pooled_expected) * (pooled_count - pooled_expected) / pooled_expected;
      ++bins;
    }
    ASSERT_GE(bins, 40);
    EXPECT_LT(chi2, chi_square_quantile(bins - 1, 1e-4)) << "p " << p.x << " " << p.y << " " << p.z;
  }
}

TEST(AreaLight, SolidAngleSamplingHasLowerVarianceCloseToALargeLight) {
  // Close under a 4 x 4 m light, area sampling's 1 / r^2 varies by orders of magnitude over the
  // light; solid-angle sampling leaves only the receiver's cosine.
  const Vec3 p(0.3f, -0.2f, 0.9f), n(0, 0, 1);
  double variance[2];
  for (AreaSampling sampling : {AreaSampling::Area, AreaSampling::SolidAngle}) {
    const Light light = ceiling_light(AreaShape::Square, 4.0f, 0.0f, 1.0f, 100.0f);
    const Estimate e =
        monte_carlo(20000, [&](uint32_t i) { return irradiance_sample(light, p, n, rand2(i, 10), sampling); });
    variance[int(sampling)] = e.standard_error * e.standard_error;
  }
  std::printf("variance ratio area / solid angle: %.1f\n", variance[0] / variance[1]);
  EXPECT_GT(variance[0] / variance[1], 1.0);
}

TEST(AreaLight, DiskAndEllipseIrradianceOnTheAxis) {
  const float h = 0.8f, power = 50.0f;
  // Disk of radius R: E = pi L R^2 / (h^2 + R^2).
  const Light disk = ceiling_light(AreaShape::Disk, 1.2f, 0.0f, h, power);
  const double l_disk = std::get<AreaLight>(disk).radiance.x, r = 0.6;
  const Estimate e_disk =
      monte_carlo(100000, [&](uint32_t i) { return irradiance_sample(disk, Vec3(0.0f), Vec3(0, 0, 1), rand2(i, 11)); });
  expect_converges(e_disk, kPiD * l_disk * r * r / (h * h + r * r), "disk");
  // Ellipse with semi-axes a, b: in polar coordinates the radial integral of L h^2 rho / (h^2 +
  // rho^2)^2 is closed, leaving E = L integral over phi of rho_max^2 / (2 (h^2 + rho_max^2)),
  // rho_max^2 = 1 / (cos^2/a^2 + sin^2/b^2); the trapezoid rule is spectrally exact for this
  // smooth periodic integrand.
  const Light ellipse = ceiling_light(AreaShape::Ellipse, 1.6f, 0.5f, h, power);
  const double l_ellipse = std::get<AreaLight>(ellipse).radiance.x, a = 0.8, b = 0.25;
  double integral = 0.0;
  constexpr int kSteps = 4096;
  for (int k = 0; k < kSteps; ++k) {
    const double phi = 2.0 * kPiD * k / kSteps;
    const double rho2 = 1.0 / (std::pow(std::cos(phi) / a, 2) + std::pow(std::sin(phi) / b, 2));
    integral += rho2 / (2.0 * (h * h + rho2)) * (2.0 * kPiD / kSteps);
  }
  const Estimate e_ellipse = monte_carlo(
      100000, [&](uint32_t i) { return irradiance_sample(ellipse, Vec3(0.0f), Vec3(0, 0, 1), rand2(i, 12)); });
  expect_converges(e_ellipse, l_ellipse * integral, "ellipse");
}

TEST(AreaLight, IsOneSided) {
  for (AreaShape shape : {AreaShape::Rectangle, AreaShape::Disk}) {
    const AreaLight light = ceiling_light(shape, 1.0f, 1.0f, 1.0f, 100.0f);
    const Vec3 above(0.1f, 0.2f, 1.5f);  // behind the light: it emits downwards
    constexpr AreaSampling kSolid = AreaSampling::SolidAngle;
    EXPECT_FALSE(sample(light, above, Vec2(0.3f, 0.6f), kSolid).valid());
    EXPECT_FALSE(evaluate(light, above, Vec3(0, 0, -1), kSolid).hit());
    EXPECT_EQ(importance(light, above, Vec3(0, 0, -1)), 0.0f);
    EXPECT_FALSE(sample(light, Vec3(3.0f, 0.0f, 1.0f), Vec2(0.3f, 0.6f), kSolid).valid());  // in its plane
    // From below, a ray going down misses; going up hits.
    EXPECT_FALSE(evaluate(light, Vec3(0.0f), Vec3(0, 0, -1), kSolid).hit());
    EXPECT_TRUE(evaluate(light, Vec3(0.0f), Vec3(0, 0, 1), kSolid).hit());
  }
}

TEST(AreaLight, RejectsInvalidSettings) {
  const Mat4 m = glm::translate(Mat4(1.0f), Vec3(0, 0, 1));
  EXPECT_THROW(AreaLight::make(AreaShape::Square, 0.0f, 0.0f, m, 1.0f, Vec3(1)), std::invalid_argument);
  EXPECT_THROW(AreaLight::make(AreaShape::Rectangle, 1.0f, -1.0f, m, 1.0f, Vec3(1)), std::invalid_argument);
  EXPECT_THROW(AreaLight::make(AreaShape::Square, 1.0f, 0.0f, m, -1.0f, Vec3(1)), std::invalid_argument);
  EXPECT_THROW(AreaLight::make(AreaShape::Square, 1.0f, 0.0f, m, 1.0f, Vec3(NAN)), std::invalid_argument);
  Mat4 sheared = m;
  sheared[1] = glm::vec4(0.5f, 1.0f, 0.0f, 0.0f);
  EXPECT_THROW(AreaLight::make(AreaShape::Square, 1.0f, 0.0f, sheared, 1.0f, Vec3(1)), std::invalid_argument);
  Mat4 flat = m;
  flat[2] = glm::vec4(0.0f);
  EXPECT_THROW(AreaLight::make(AreaShape::Square, 1.0f, 0.0f, flat, 1.0f, Vec3(1)), std::invalid_argument);
  EXPECT_NO_THROW(AreaLight::make(AreaShape::Square, 1.0f, 0.0f, m, 0.0f, Vec3(1)));  // an off light is fine
}

TEST(LightSelector, ProbabilitiesSumToOneAndFollowTheImportance) {
  std::vector<Light> lights = {
      PointLight::make(Vec3(0, 0, 2), 100.0f, Vec3(1.0f)),
      PointLight::make(Vec3(3, 0, 1), 40.0f, Vec3(1.0f, 0.0f, 0.0f), 0.2f),
      ceiling_light(AreaShape::Rectangle, 1.0f, 2.0f, 3.0f, 200.0f),
      PointLight::make(Vec3(0, 0, -2), 100.0f, Vec3(1.0f)),       // below the receiver: cannot contribute
      ceiling_light(AreaShape::Disk, 1.0f, 0.0f, -1.0f, 100.0f),  // faces away
  };
  const LightSelector selector(lights);
  const Vec3 p(0.2f, 0.1f, 0.0f), n(0, 0, 1);
  double total_importance = 0.0, total_probability = 0.0;
  for (const Light& l : lights) total_importance += light_importance(l, p, n);
  std::vector<double> counts(lights.size(), 0.0);
  constexpr int kN = 100000;
  for (int i = 0; i < kN; ++i) {
    const LightSelection s = selector.select(p, n, (i + 0.5f) / kN);  // stratified: counts are exact
    ASSERT_TRUE(s.found());
    EXPECT_FLOAT_EQ(s.probability, selector.probability(p, n, size_t(s.index)));
    counts[size_t(s.index)] += 1.0;
  }
  for (size_t i = 0; i < lights.size(); ++i) {
    const double expected = light_importance(lights[i], p, n) / total_importance;
    total_probability += selector.probability(p, n, i);
    EXPECT_NEAR(selector.probability(p, n, i), expected, 1e-6);
    // Stratified u: each light gets its share to within one sample per boundary.
    EXPECT_NEAR(counts[i] / kN, expected, 2.0 / kN);
  }
  EXPECT_NEAR(total_probability, 1.0, 1e-6);
  EXPECT_EQ(counts[3], 0.0);
  EXPECT_EQ(counts[4], 0.0);
  EXPECT_FALSE(LightSelector(std::vector<Light>(lights.begin() + 3, lights.end())).select(p, n, 0.5f).found());
}

TEST(LightSelector, OneSampleEstimateIsUnbiased) {
  // Two point lights and a rectangle above a receiver: choosing one light per sample by
  // importance, divided by its probability, converges to the sum of their closed forms.
  std::vector<Light> lights = {
      PointLight::make(Vec3(0.5f, 0, 1), 30.0f, Vec3(1.0f)),
      PointLight::make(Vec3(-2, 1, 3), 300.0f, Vec3(1.0f)),
      ceiling_light(AreaShape::Rectangle, 1.0f, 2.0f, 1.5f, 100.0f),
  };
  const LightSelector selector(lights);
  const Vec3 p(0.0f), n(0, 0, 1);
  double exact = 0.0;
  for (Vec3 position : {Vec3(0.5f, 0, 1), Vec3(-2, 1, 3)}) {
    const double power = position.z == 1 ? 30.0 : 300.0, r2 = glm::dot(position, position);
    exact += power / (4.0 * kPiD) * (position.z / std::sqrt(r2)) / r2;
  }
  exact += 100.0 / (4.0 * 2.0) * over_rectangle(corner_irradiance_over_radiance, -0.5, 0.5, -1.0, 1.0, 1.5);
  const Estimate e = monte_carlo(200000, [&](uint32_t i) {
    const LightSelection chosen = selector.select(p, n, random_float(i, 0, 2, 13));
    if (!chosen.found()) return 0.0;
    return irradiance_sample(lights[size_t(chosen.index)], p, n, rand2(i, 13)) / chosen.probability;
  });
  expect_converges(e, exact, "light selection");
}

TEST(LightSelector, ImportanceIsPositiveWhereverALightContributes) {
  // Random receivers around a few lights: a sample that brings light implies a positive
  // importance, otherwise selection would be biased.
  std::vector<Light> lights = {
      PointLight::make(Vec3(0, 0, 0), 10.0f, Vec3(1.0f), 0.5f),
      ceiling_light(AreaShape::Rectangle, 2.0f, 1.0f, 0.0f, 10.0f),
      ceiling_light(AreaShape::Ellipse, 2.0f, 1.0f, 0.0f, 10.0f),
  };
  int contributing = 0;
  for (uint32_t j = 0; j < 2000; ++j) {
    const Vec3 p = 4.0f * (Vec3(rand2(j, 14), random_float(j, 0, 2, 14)) - Vec3(0.5f));
    const Vec3 n = glm::normalize(Vec3(rand2(j, 15), random_float(j, 0, 2, 15)) - Vec3(0.5f));
    for (const Light& light : lights) {
      bool contributes = false;
      for (uint32_t i = 0; i < 16 && !contributes; ++i)
        contributes = irradiance_sample(light, p, n, rand2(i, 16 + j)) > 0.0;
      if (contributes) {
        ++contributing;
        EXPECT_GT(light_importance(light, p, n), 0.0f);
      }
    }
  }
  EXPECT_GT(contributing, 500);
}
