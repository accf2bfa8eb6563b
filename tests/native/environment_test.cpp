// The environment map and its sampler: the piecewise-constant distribution's cell frequencies
// and density, the environment's solid-angle density integrating to one over the sphere (with a
// rotation and a scale in the mapping too), sample() and pdf() agreeing, and Blender's
// equirectangular convention (the image centre along -X, the top row up).
#include "scene/environment.h"

#include "light_estimates.h"

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <stdexcept>
#include <vector>

using namespace toyrt;
using namespace toyrt::testing;

namespace {

// A w x h RGB float image from a function of (column, row from the bottom).
template <class F>
Texture image(int w, int h, F f) {
  std::vector<float> px;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Vec3 c = f(x, y);
      px.insert(px.end(), {c.x, c.y, c.z});
    }
  return Texture::from_floats(w, h, 3, px, ColorEncoding::Linear);
}

Vec3 uniform_sphere(uint32_t i, uint32_t seed) { return sample_uniform_sphere(rand2(i, seed)); }

}  // namespace

TEST(Distribution2D, CellsAreChosenInProportionToTheirWeights) {
  const std::vector<float> w = {1, 0, 3, 2, 0.5f, 0, 0, 0, 4, 1, 1, 1};  // 4 x 3
  const Distribution2D d = Distribution2D::build(w, 4, 3);
  std::vector<int> count(12, 0);
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    float pdf = 0.0f;
    const Vec2 p = d.sample(rand2(uint32_t(i), 21), pdf);
    const int cell = int(p.y * 3) * 4 + int(p.x * 4);
    ++count[size_t(cell)];
    ASSERT_GT(pdf, 0.0f);
    ASSERT_FLOAT_EQ(pdf, d.pdf(p));
  }
  const double total = 13.5;
  for (int c = 0; c < 12; ++c) {
    const double p = w[size_t(c)] / total;
    EXPECT_NEAR(count[size_t(c)] / double(n), p, 5.0 * std::sqrt(p * (1 - p) / n) + 1e-9) << "cell " << c;
    EXPECT_NEAR(d.density[size_t(c)], w[size_t(c)] / (total / 12.0), 1e-5);
  }
}

TEST(Distribution2D, AnAllZeroGridIsUniformAndBadWeightsAreRefused) {
  const Distribution2D d = Distribution2D::build(std::vector<float>(6, 0.0f), 3, 2);
  EXPECT_FLOAT_EQ(d.pdf(Vec2(0.1f, 0.9f)), 1.0f);
  EXPECT_THROW(Distribution2D::build({1.0f, -1.0f}, 2, 1), std::invalid_argument);
  EXPECT_THROW(Distribution2D::build({1.0f, NAN}, 2, 1), std::invalid_argument);
  EXPECT_THROW(Distribution2D::build({1.0f}, 2, 1), std::invalid_argument);
}

TEST(Environment, DensityIntegratesToOneOverTheSphereWhateverTheMapping) {
  // A sky with a small bright patch: the density is far from uniform.
  const Texture sky = image(64, 32, [](int x, int y) { return Vec3(x == 40 && y == 24 ? 500.0f : 0.2f + 0.01f * y); });
  const glm::mat3 rotation = glm::mat3(glm::rotate(Mat4(1.0f), 0.7f, glm::normalize(Vec3(1, 2, 3))));
  for (const glm::mat3& m :
       {glm::mat3(1.0f), rotation, rotation * glm::mat3(glm::scale(Mat4(1.0f), Vec3(2, 1, 0.5f)))}) {
    const Environment env = make_environment(0, sky, Vec3(1.0f), m);
    const Estimate e = monte_carlo(
        400000, [&](uint32_t i) { return double(environment_pdf(env, uniform_sphere(i, 22))) * 4.0 * kPiD; });
    expect_converges(e, 1.0, "environment pdf");
  }
}

TEST(Environment, SamplesCarryTheDensityAndRadianceOfTheirDirection) {
  const Texture sky = image(16, 8, [](int x, int y) { return Vec3(1.0f + x, 1.0f + y, 0.5f); });
  const glm::mat3 m = glm::mat3(glm::rotate(Mat4(1.0f), 1.1f, Vec3(0, 0, 1)));
  const Environment env = make_environment(0, sky, Vec3(2.0f), m);
  for (uint32_t i = 0; i < 256; ++i) {
    const EnvironmentSample s = sample_environment(env, sky, rand2(i, 23));
    ASSERT_GT(s.pdf, 0.0f);
    EXPECT_NEAR(glm::length(s.wi), 1.0f, 1e-5f);
    EXPECT_NEAR(s.pdf, environment_pdf(env, s.wi), 1e-3f * s.pdf);
    const Vec3 r = environment_radiance(env, sky, s.wi);
    EXPECT_EQ(s.radiance, r);
  }
}

TEST(Environment, FollowsBlendersEquirectangularConvention) {
  // Texel centres: column x at u = (x + 0.5) / 4, row y at v = (y + 0.5) / 2. The image's centre
  // (u = 0.5) looks along -X, u = 0.25 along -Y... u = 0.5 - atan2(y, x) / (2 pi); v = 1 is up.
  const Texture sky = image(4, 2, [](int x, int y) { return Vec3(float(x), float(y), 1.0f); });
  const Environment env = make_environment(0, sky, Vec3(1.0f), glm::mat3(1.0f));
  const auto at = [&](float u, float v) {
    const float phi = (0.5f - u) * 2.0f * kPi, theta = (1.0f - v) * kPi;
    return environment_radiance(
        env, sky, Vec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)));
  };
  for (int x = 0; x < 4; ++x)
    for (int y = 0; y < 2; ++y) {
      const Vec3 r = at((x + 0.5f) / 4.0f, (y + 0.5f) / 2.0f);
      EXPECT_NEAR(r.x, float(x), 1e-4f);
      EXPECT_NEAR(r.y, float(y), 1e-4f);
    }
  // -X is the seam between columns 1 and 2 (u = 0.5), halfway between them, in the upper row.
  EXPECT_NEAR(environment_radiance(env, sky, glm::normalize(Vec3(-1, 0, 0.7f))).x, 1.5f, 1e-4f);
}

TEST(Environment, RefusesBadSettings) {
  const Texture sky = image(2, 1, [](int, int) { return Vec3(1.0f); });
  EXPECT_THROW(make_environment(0, sky, Vec3(-1.0f), glm::mat3(1.0f)), std::invalid_argument);
  EXPECT_THROW(make_environment(0, sky, Vec3(NAN), glm::mat3(1.0f)), std::invalid_argument);
  EXPECT_THROW(make_environment(0, sky, Vec3(1.0f), glm::mat3(0.0f)), std::invalid_argument);
}
