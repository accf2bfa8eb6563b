// The Normal Map node's normal (materials/normal_map.h): the texel's vector in the tangent frame,
// the conventions and strength rules of Blender 3.x and 4.x+, and the below-surface fix (the
// bent normal's mirror of the view direction stays above the geometric surface).
#include "materials/normal_map.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace toyrt;

namespace {

constexpr float kEps = 1e-5f;

void expect_near(const Vec3& a, const Vec3& b, float eps = kEps) {
  EXPECT_NEAR(a.x, b.x, eps);
  EXPECT_NEAR(a.y, b.y, eps);
  EXPECT_NEAR(a.z, b.z, eps);
}

Vec3 texel_of(const Vec3& n) { return 0.5f * (n + 1.0f); }

}  // namespace

TEST(NormalMap, FlatTexelGivesTheSmoothNormal) {
  const MaterialNormalMap map{0};
  const Vec3 n = normal_map_vector(map, Vec3(0.5f, 0.5f, 1.0f));
  // A smooth normal of any length, a tangent orthogonal to it: the normal, unit.
  expect_near(tangent_space_normal(map, n, Vec3(0, 2, 0), 1.0f, Vec3(0, 0, 3)), Vec3(0, 0, 1));
}

TEST(NormalMap, TexelIsReadInTheTangentFrameWithItsBitangentSign) {
  const MaterialNormalMap map{0};
  const Vec3 encoded = glm::normalize(Vec3(0.3f, 0.4f, 0.8f));
  const Vec3 n = normal_map_vector(map, texel_of(encoded));
  // T = x, N = z: B = sign cross(N, T) = sign y.
  expect_near(tangent_space_normal(map, n, Vec3(1, 0, 0), 1.0f, Vec3(0, 0, 1)), encoded);
  expect_near(tangent_space_normal(map, n, Vec3(1, 0, 0), -1.0f, Vec3(0, 0, 1)),
              Vec3(encoded.x, -encoded.y, encoded.z));
}

TEST(NormalMap, DirectXConventionNegatesGreen) {
  MaterialNormalMap map{0};
  map.directx = true;
  expect_near(normal_map_vector(map, Vec3(0.25f, 0.75f, 1.0f)), Vec3(-0.5f, -0.5f, 1.0f));
  map.directx = false;
  expect_near(normal_map_vector(map, Vec3(0.25f, 0.75f, 1.0f)), Vec3(-0.5f, 0.5f, 1.0f));
  map.space = NormalMapSpace::BlenderObject;  // Blender's own object space: y and z negated
  expect_near(normal_map_vector(map, Vec3(0.25f, 0.75f, 1.0f)), Vec3(-0.5f, -0.5f, -1.0f));
}

TEST(NormalMap, TangentStrengthScalesTheTexelAsBlender4) {
  MaterialNormalMap map{0};
  map.strength = 0.5f;
  const Vec3 n(0.6f, 0.0f, 0.8f);
  // n.xy * s, n.z = 1 + (n.z - 1) min(s, 1) = 0.9.
  expect_near(tangent_space_normal(map, n, Vec3(1, 0, 0), 1.0f, Vec3(0, 0, 1)), glm::normalize(Vec3(0.3f, 0, 0.9f)));
  map.strength = 0.0f;
  expect_near(tangent_space_normal(map, n, Vec3(1, 0, 0), 1.0f, Vec3(0, 0, 1)), Vec3(0, 0, 1));
  // No second blend in tangent space.
  expect_near(blend_normal_strength(map, Vec3(0.6f, 0.0f, 0.8f), Vec3(0, 0, 1)), Vec3(0.6f, 0.0f, 0.8f));
}

TEST(NormalMap, BlendStrengthMixesWorldNormalsAsBlender3) {
  MaterialNormalMap map{0};
  map.strength_mode = NormalStrength::Blend;
  map.strength = 0.5f;
  const Vec3 n(0.6f, 0.0f, 0.8f);
  expect_near(tangent_space_normal(map, n, Vec3(1, 0, 0), 1.0f, Vec3(0, 0, 1)), n);  // not scaled here
  expect_near(blend_normal_strength(map, n, Vec3(0, 0, 1)), glm::normalize(Vec3(0.3f, 0.0f, 0.9f)));
  map.strength = -2.0f;  // clamped to 0: the smooth normal
  expect_near(blend_normal_strength(map, n, Vec3(0, 0, 1)), Vec3(0, 0, 1));
}

TEST(NormalMap, DegenerateResultFallsBackToTheSmoothNormal) {
  const MaterialNormalMap map{0};
  const Vec3 ns(0, 0, 1);
  expect_near(blend_normal_strength(map, Vec3(0.0f), ns), ns);
  expect_near(blend_normal_strength(map, Vec3(NAN, 0.0f, 1.0f), ns), ns);
  // A zero tangent and a texel along it: zero, then the fallback.
  EXPECT_EQ(tangent_space_normal(map, Vec3(1, 0, 0), Vec3(0.0f), 1.0f, Vec3(0.0f)), Vec3(0.0f));
}

TEST(NormalMap, ValidNormalIsKept) {
  const Vec3 ng(0, 0, 1), wo = glm::normalize(Vec3(0.2f, 0.1f, 1.0f)), n = glm::normalize(Vec3(0.3f, 0.0f, 1.0f));
  EXPECT_EQ(valid_reflection_normal(ng, wo, n), n);
}

TEST(NormalMap, NormalBentBelowTheSurfaceReflectsJustAboveIt) {
  const Vec3 ng(0, 0, 1);
  for (float view : {0.0f, 0.5f, 1.2f, 1.5f})
    for (float bend : {0.8f, 1.2f, 1.5f, 2.0f}) {
      for (float side : {1.0f, -1.0f}) {
        const Vec3 wo(side * std::sin(view), 0.0f, std::cos(view));
        const Vec3 n(std::sin(bend), 0.0f, std::cos(bend));
        const float iz = wo.z, threshold = std::min(0.9f * iz, 0.01f);
        const Vec3 r0 = 2.0f * glm::dot(n, wo) * n - wo;
        const Vec3 fixed = valid_reflection_normal(ng, wo, n);
        ASSERT_TRUE(is_finite(fixed));
        EXPECT_NEAR(glm::length(fixed), 1.0f, 1e-5f);
        const Vec3 r = 2.0f * glm::dot(fixed, wo) * fixed - wo;
        if (r0.z >= threshold) {
          EXPECT_EQ(fixed, n.z < 0.0f ? -n : n);  // the same mirror, on the surface's side
        } else {
          // On the threshold, turned from n towards ng in their plane.
          EXPECT_NEAR(r.z, threshold, 2e-4f) << view << " " << bend << " " << side;
          EXPECT_NEAR(fixed.y, 0.0f, 1e-6f);
          EXPECT_GT(fixed.z, n.z);
          EXPECT_GE(fixed.x, 0.0f);
        }
      }
    }
}

TEST(NormalMap, NormalOppositeTheSurfaceBecomesTheSurfaceNormal) {
  const Vec3 ng(0, 0, 1), wo = glm::normalize(Vec3(0.3f, 0.0f, 1.0f));
  expect_near(valid_reflection_normal(ng, wo, -ng), ng);
}

TEST(NormalMap, BadValuesAreRefusedByName) {
  MaterialNormalMap map{3};
  EXPECT_THROW(map.check(2), std::invalid_argument);
  EXPECT_NO_THROW(map.check(4));
  map.strength = NAN;
  EXPECT_THROW(map.check(4), std::invalid_argument);
}
