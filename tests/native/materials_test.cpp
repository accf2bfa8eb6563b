// Materials against exact answers: Fresnel values (0.04 at normal incidence for ior 1.5, 1 at
// grazing and beyond the critical angle, R + T = 1 from the transmission amplitudes, Brewster's
// angle), Snell's law both ways, total internal reflection, a slab giving back the incoming
// direction, the shading/geometric normal rules; texture lookups at texel centres, halfway and
// across the wrap-around edge; the sRGB decode; Lambert's albedo / pi.
#include "materials/fresnel.h"
#include "materials/lambert.h"
#include "materials/material.h"
#include "materials/refraction.h"
#include "materials/texture.h"
#include "sampling/rng.h"
#include "sampling/warp.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

using namespace toyrt;

namespace {

constexpr double kPiD = 3.14159265358979323846;
const Vec3 kUp(0.0f, 0.0f, 1.0f);

Vec2 rand2(uint32_t i, uint32_t seed) { return {random_float(i, 0, 0, seed), random_float(i, 0, 1, seed)}; }

// A unit direction at angle theta from +z (or from -z when `below`), azimuth phi.
Vec3 direction(double theta, double phi, bool below = false) {
  const double z = std::cos(theta) * (below ? -1.0 : 1.0);
  return Vec3(float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)), float(z));
}

double sin_to_normal(const Vec3& d, const Vec3& n) { return glm::length(glm::cross(d, n)); }

}  // namespace

TEST(Fresnel, NormalIncidenceIsFourPercentForIor1_5) {
  const double expected = std::pow((1.0 - 1.5) / (1.0 + 1.5), 2);  // 0.04
  EXPECT_NEAR(fresnel_dielectric(1.0f, 1.5f), expected, 1e-7);
  EXPECT_NEAR(fresnel_dielectric(1.0f, 1.0f / 1.5f), expected, 1e-7);  // the same from inside
  EXPECT_NEAR(fresnel_dielectric(0.3f, 1.0f), 0.0f, 1e-12f);           // no interface, no reflection
}

TEST(Fresnel, GoesToOneAtGrazing) {
  EXPECT_NEAR(fresnel_dielectric(0.0f, 1.5f), 1.0f, 1e-6f);
  EXPECT_GT(fresnel_dielectric(1e-3f, 1.5f), 0.99f);
  // Entering glass, reflectance grows monotonically from Brewster's angle to grazing.
  float previous = fresnel_dielectric(std::cos(std::atan(1.5f)), 1.5f);
  for (double theta = std::atan(1.5) + 0.01; theta < kPiD / 2; theta += 0.01) {
    const float f = fresnel_dielectric(float(std::cos(theta)), 1.5f);
    EXPECT_GT(f, previous);
    previous = f;
  }
}

TEST(Fresnel, IsOneBeyondTheCriticalAngle) {
  const double critical = std::asin(1.0 / 1.5);
  for (double theta = critical + 1e-3; theta < kPiD / 2; theta += 0.05)
    EXPECT_EQ(fresnel_dielectric(float(std::cos(theta)), 1.0f / 1.5f), 1.0f);
  EXPECT_LT(fresnel_dielectric(float(std::cos(critical - 1e-2)), 1.0f / 1.5f), 1.0f);
}

TEST(Fresnel, ReflectanceAndTransmittanceSumToOne) {
  // T from Fresnel's transmission amplitudes t_s = 2 cos_i / (cos_i + eta cos_t),
  // t_p = 2 cos_i / (eta cos_i + cos_t), weighted by the beam's area and speed change
  // eta cos_t / cos_i: energy conservation says R + T = 1, checking R independently.
  for (double eta : {1.5, 1.0 / 1.5, 1.33, 2.4})
    for (int k = 0; k < 50; ++k) {
      const double cos_i = 0.01 + 0.99 * random_float(k, 0, 0, 1);
      const double sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
      if (sin2_t >= 1.0) continue;
      const double cos_t = std::sqrt(1.0 - sin2_t);
      const double ts = 2.0 * cos_i / (cos_i + eta * cos_t), tp = 2.0 * cos_i / (eta * cos_i + cos_t);
      const double transmittance = eta * cos_t / cos_i * 0.5 * (ts * ts + tp * tp);
      EXPECT_NEAR(fresnel_dielectric(float(cos_i), float(eta)) + transmittance, 1.0, 1e-5);
    }
}

TEST(Fresnel, BrewsterAngleReflectsOnlySPolarisation) {
  // At tan(theta_B) = eta, theta_i + theta_t = 90 degrees and r_p = 0, so
  // F = r_s^2 / 2 = sin^2(theta_i - theta_t) / 2.
  for (double eta : {1.5, 1.0 / 1.5}) {
    const double theta_i = std::atan(eta), theta_t = kPiD / 2 - theta_i;
    EXPECT_NEAR(fresnel_dielectric(float(std::cos(theta_i)), float(eta)),
                0.5 * std::pow(std::sin(theta_i - theta_t), 2), 1e-6);
  }
}

TEST(Fresnel, SameReflectanceFromBothSidesOfTheInterface) {
  for (int k = 0; k < 50; ++k) {
    const double theta_i = 1.5 * random_float(k, 0, 0, 2);
    const double theta_t = std::asin(std::sin(theta_i) / 1.5);
    EXPECT_NEAR(fresnel_dielectric(float(std::cos(theta_i)), 1.5f),
                fresnel_dielectric(float(std::cos(theta_t)), 1.0f / 1.5f), 1e-5);
  }
}

TEST(Fresnel, GlassChoosesReflectionWithProbabilityF) {
  const FresnelDielectric glass = FresnelDielectric::make(1.5f);
  for (double theta : {0.0, 0.8, 1.4}) {
    const Vec3 wo = direction(theta, 0.3);
    const float f = fresnel_dielectric(float(std::cos(theta)), 1.5f);
    constexpr int kN = 10000;
    int reflected = 0;
    for (int i = 0; i < kN; ++i) {
      const SpecularSample s = sample(glass, wo, kUp, kUp, (i + 0.5f) / kN);  // stratified u
      reflected += s.reflected;
      EXPECT_FLOAT_EQ(s.probability, s.reflected ? f : 1.0f - f);
      if (s.reflected)
        EXPECT_NEAR(glm::length(s.wi - reflect(wo, kUp)), 0.0f, 1e-6f);
      else
        EXPECT_LT(s.wi.z, 0.0f);
    }
    EXPECT_NEAR(double(reflected) / kN, f, 1.0 / kN);
  }
  // Beyond the critical angle, from inside: always reflected.
  const SpecularSample tir = sample(glass, direction(1.2, 0.0, true), kUp, kUp, 0.999f);
  EXPECT_TRUE(tir.reflected && tir.total_internal_reflection);
  EXPECT_FLOAT_EQ(tir.probability, 1.0f);
}

TEST(Fresnel, SplitGivesBothBranchesWeightedFAndOneMinusF) {
  const FresnelDielectric glass = FresnelDielectric::make(1.5f);
  for (double theta : {0.0, 0.8, 1.4}) {
    const Vec3 wo = direction(theta, 0.3);
    const float f = fresnel_dielectric(float(std::cos(theta)), 1.5f);
    SpecularSample b[2];
    ASSERT_EQ(split(glass, wo, kUp, kUp, b), 2);
    EXPECT_TRUE(b[0].reflected && !b[1].reflected);
    EXPECT_FLOAT_EQ(b[0].probability, f);
    EXPECT_EQ(b[0].probability + b[1].probability, 1.0f);
    // The same directions sample() picks for each branch.
    EXPECT_NEAR(glm::length(b[0].wi - sample(glass, wo, kUp, kUp, 0.0f).wi), 0.0f, 1e-7f);
    EXPECT_NEAR(glm::length(b[1].wi - sample(glass, wo, kUp, kUp, 1.0f).wi), 0.0f, 1e-7f);
  }
  // Total internal reflection: one branch, all of the weight.
  SpecularSample b[2];
  ASSERT_EQ(split(glass, direction(1.2, 0.0, true), kUp, kUp, b), 1);
  EXPECT_TRUE(b[0].reflected && b[0].total_internal_reflection);
  EXPECT_EQ(b[0].probability, 1.0f);
}

TEST(Refraction, SnellsLawHoldsBothWays) {
  const float ior = 1.5f;
  const PerfectRefraction glass = PerfectRefraction::make(ior);
  for (int k = 0; k < 200; ++k) {
    const bool from_inside = k % 2;
    const double critical = std::asin(1.0 / ior);
    const double theta = (from_inside ? critical : kPiD / 2) * 0.999 * random_float(k, 0, 0, 3);
    const Vec3 wo = direction(theta, 2.0 * kPiD * random_float(k, 0, 1, 3), from_inside);
    const SpecularSample s = sample(glass, wo, kUp, kUp);
    ASSERT_FALSE(s.reflected);
    EXPECT_EQ(s.entering, !from_inside);
    EXPECT_NEAR(glm::length(s.wi), 1.0f, 1e-6f);
    // n1 sin(theta1) = n2 sin(theta2), the ray crosses the surface, and stays in the plane of incidence.
    const double n1 = from_inside ? ior : 1.0, n2 = from_inside ? 1.0 : ior;
    EXPECT_NEAR(n1 * sin_to_normal(wo, kUp), n2 * sin_to_normal(s.wi, kUp), 2e-6);
    EXPECT_LT(s.wi.z * wo.z, 0.0f);
    EXPECT_NEAR(glm::dot(glm::cross(wo, kUp), s.wi), 0.0f, 1e-6f);
    // Leaving towards the far side: the offset normal points there.
    EXPECT_GT(glm::dot(s.offset_normal, s.wi), 0.0f);
  }
}

TEST(Refraction, TotalInternalReflectionMirrors) {
  const PerfectRefraction glass = PerfectRefraction::make(1.5f);
  const double critical = std::asin(1.0 / 1.5);
  for (double theta = critical + 1e-3; theta < kPiD / 2; theta += 0.05) {
    const Vec3 wo = direction(theta, 0.7, true);  // inside the object, below the surface
    const SpecularSample s = sample(glass, wo, kUp, kUp);
    EXPECT_TRUE(s.reflected && s.total_internal_reflection);
    EXPECT_NEAR(glm::length(s.wi - Vec3(-wo.x, -wo.y, wo.z)), 0.0f, 1e-6f);  // the mirror direction
    EXPECT_LT(s.offset_normal.z, 0.0f);                                      // stays inside
  }
  EXPECT_FALSE(sample(glass, direction(critical - 1e-2, 0.7, true), kUp, kUp).reflected);
}

TEST(Refraction, SlabGivesBackTheOriginalDirection) {
  // In through the top face (normal +z), out through the parallel bottom face (normal -z).
  const PerfectRefraction glass = PerfectRefraction::make(1.7f);
  for (int k = 0; k < 100; ++k) {
    const Vec3 d = -direction(1.5 * random_float(k, 0, 0, 4), 2.0 * kPiD * random_float(k, 0, 1, 4));  // going down
    const SpecularSample in = sample(glass, -d, kUp, kUp);
    ASSERT_FALSE(in.reflected);
    const SpecularSample out = sample(glass, -in.wi, -kUp, -kUp);
    ASSERT_FALSE(out.reflected);
    // Float rounding, amplified near grazing exit, where d(theta_out) / d(theta_in) grows as
    // 1 / cos(theta_out): a few 1e-6 at 86 degrees.
    EXPECT_NEAR(glm::length(out.wi - d), 0.0f, 1e-5f);
  }
}

TEST(Refraction, GeometricNormalDecidesTheSideShadingNormalBends) {
  const PerfectRefraction glass = PerfectRefraction::make(1.5f);
  const Vec3 ns = glm::normalize(Vec3(0.2f, 0.0f, 1.0f));  // a smooth normal tilted from the facet's
  const Vec3 wo = direction(0.4, 0.0);
  const SpecularSample s = sample(glass, wo, kUp, ns);
  EXPECT_TRUE(s.entering);
  // Snell's law holds about the shading normal...
  EXPECT_NEAR(sin_to_normal(wo, ns), 1.5 * sin_to_normal(s.wi, ns), 2e-6);
  // ...and a flipped shading normal (inverted vertex normals) changes nothing: ng decides.
  const SpecularSample flipped = sample(glass, wo, kUp, -ns);
  EXPECT_NEAR(glm::length(flipped.wi - s.wi), 0.0f, 1e-6f);
  EXPECT_TRUE(flipped.entering);
}

TEST(Refraction, DisagreeingShadingNormalFallsBackToGeometric) {
  const PerfectRefraction glass = PerfectRefraction::make(1.5f);
  // wo is above the facet but below the shading normal's tangent plane: bend with ng instead.
  const Vec3 ns = glm::normalize(Vec3(-1.0f, 0.0f, 0.3f));
  const Vec3 wo = direction(1.2, 0.0);
  ASSERT_GT(glm::dot(wo, kUp), 0.0f);
  ASSERT_LT(glm::dot(wo, ns), 0.0f);
  const SpecularSample s = sample(glass, wo, kUp, ns), geometric = sample(glass, wo, kUp, kUp);
  EXPECT_NEAR(glm::length(s.wi - geometric.wi), 0.0f, 1e-6f);
  // Whatever the shading normal, refracted rays go below the real surface and reflected ones above.
  for (int k = 0; k < 2000; ++k) {
    const Vec3 shading = glm::normalize(kUp + 0.9f * (sample_uniform_sphere(rand2(k, 5))));
    const bool inside = k % 2;
    const Vec3 w = direction(1.55 * random_float(k, 0, 2, 5), 6.28 * random_float(k, 0, 3, 5), inside);
    const SpecularSample r = sample(glass, w, kUp, shading);
    const float side = r.wi.z * (inside ? -1.0f : 1.0f);  // positive: back on wo's side
    EXPECT_EQ(side > 0.0f, r.reflected);
    EXPECT_GT(glm::dot(r.offset_normal, r.wi), 0.0f);
  }
}

TEST(Refraction, RejectsInvalidIor) {
  EXPECT_THROW(PerfectRefraction::make(0.0f), std::invalid_argument);
  EXPECT_THROW(FresnelDielectric::make(-1.5f), std::invalid_argument);
  EXPECT_THROW(FresnelDielectric::make(NAN), std::invalid_argument);
}

TEST(Texture, TexelCentresReturnTheTexel) {
  // 4 x 2 RGBA, rows bottom-up: texel (i, j) has value (i, j, i + 10 j, 0.5).
  std::vector<float> data;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 4; ++i) data.insert(data.end(), {float(i), float(j), float(i + 10 * j), 0.5f});
  const Texture t = Texture::from_floats(4, 2, 4, data, ColorEncoding::Linear);
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 4; ++i) {
      const glm::vec4 v = t.lookup(Vec2((i + 0.5f) / 4.0f, (j + 0.5f) / 2.0f));
      EXPECT_EQ(v, glm::vec4(float(i), float(j), float(i + 10 * j), 0.5f)) << i << " " << j;
    }
  // A width that is not a power of two: exact up to rounding of (i + 0.5) / w.
  std::vector<float> rgb;
  for (int i = 0; i < 7; ++i) rgb.insert(rgb.end(), {float(i), 1.0f, 2.0f});
  const Texture row = Texture::from_floats(7, 1, 3, rgb, ColorEncoding::Linear);
  for (int i = 0; i < 7; ++i) {
    EXPECT_NEAR(row.lookup(Vec2((i + 0.5f) / 7.0f, 0.5f)).x, float(i), 1e-5f);
    EXPECT_EQ(row.lookup(Vec2((i + 0.5f) / 7.0f, 0.5f)).w, 1.0f);  // RGB: alpha 1
  }
}

TEST(Texture, HalfwayBetweenTexelsIsTheirAverage) {
  const std::vector<float> data = {0, 0, 0, 2, 4, 6, 10, 20, 30, 1, 1, 1};  // 2 x 2 RGB
  const Texture t = Texture::from_floats(2, 2, 3, data, ColorEncoding::Linear);
  EXPECT_EQ(t.lookup(Vec2(0.5f, 0.25f)), glm::vec4(1, 2, 3, 1));             // between (0,0) and (1,0)
  EXPECT_EQ(t.lookup(Vec2(0.25f, 0.5f)), glm::vec4(5, 10, 15, 1));           // between (0,0) and (0,1)
  EXPECT_EQ(t.lookup(Vec2(0.5f, 0.5f)), glm::vec4(3.25f, 6.25f, 9.25f, 1));  // all four
  // v = 0 is the bottom row (Blender's order): row 0 comes first in the data.
  EXPECT_EQ(t.texel(1, 0), glm::vec4(2, 4, 6, 1));
}

TEST(Texture, WrapsAroundAtTheEdges) {
  const std::vector<float> data = {1, 1, 1, 5, 5, 5, 9, 9, 9};  // 3 x 1 RGB
  const Texture t = Texture::from_floats(3, 1, 3, data, ColorEncoding::Linear);
  // u = 0 and u = 1 lie halfway between the last and the first column.
  EXPECT_EQ(t.lookup(Vec2(0.0f, 0.5f)).x, 5.0f);
  EXPECT_EQ(t.lookup(Vec2(1.0f, 0.5f)).x, 5.0f);
  EXPECT_NEAR(t.lookup(Vec2(-2.0f + 0.5f / 3.0f, 0.5f)).x, 1.0f, 1e-5f);  // repeat
  EXPECT_NEAR(t.lookup(Vec2(7.0f + 2.5f / 3.0f, 3.25f)).x, 9.0f, 1e-5f);
  // Vertically the same: a 1 x 2 texture at v = 0 averages its two rows.
  const Texture column = Texture::from_floats(1, 2, 3, {0, 0, 0, 4, 4, 4}, ColorEncoding::Linear);
  EXPECT_EQ(column.lookup(Vec2(0.3f, 0.0f)).x, 2.0f);
  EXPECT_EQ(column.lookup(Vec2(0.3f, 1.0f)).x, 2.0f);
}

TEST(Texture, SrgbDecodesWithTheExactTransferFunction) {
  const float expected_half = float(std::pow((0.5 + 0.055) / 1.055, 2.4));  // 0.2140
  EXPECT_NEAR(srgb_to_linear(0.5f), expected_half, 1e-6f);
  EXPECT_NEAR(srgb_to_linear(0.02f), 0.02f / 12.92f, 1e-9f);  // the linear segment
  EXPECT_NEAR(srgb_to_linear(1.0f), 1.0f, 1e-6f);
  EXPECT_EQ(srgb_to_linear(0.0f), 0.0f);
  // The two pieces meet at 0.04045 (continuity of the standard's curve).
  EXPECT_NEAR(0.04045f / 12.92f, std::pow((0.04045 + 0.055) / 1.055, 2.4), 1e-6);
  // 8-bit sRGB images: v / 255 decoded, alpha kept linear.
  const Texture t = Texture::from_bytes(1, 1, 4, {0, 128, 255, 128}, ColorEncoding::Srgb);
  EXPECT_EQ(t.texel(0, 0).x, 0.0f);
  EXPECT_NEAR(t.texel(0, 0).y, std::pow((128.0 / 255.0 + 0.055) / 1.055, 2.4), 1e-6);
  EXPECT_NEAR(t.texel(0, 0).z, 1.0f, 1e-6f);
  EXPECT_NEAR(t.texel(0, 0).w, 128.0f / 255.0f, 1e-7f);
  const Texture linear = Texture::from_bytes(1, 1, 3, {0, 128, 255}, ColorEncoding::Linear);
  EXPECT_NEAR(linear.texel(0, 0).y, 128.0f / 255.0f, 1e-7f);
}

TEST(Texture, RejectsInvalidImages) {
  EXPECT_THROW(Texture::from_floats(0, 1, 3, {}, ColorEncoding::Linear), std::invalid_argument);
  EXPECT_THROW(Texture::from_floats(1, 1, 2, {0, 0}, ColorEncoding::Linear), std::invalid_argument);
  EXPECT_THROW(Texture::from_floats(2, 1, 3, {0, 0, 0}, ColorEncoding::Linear), std::invalid_argument);
  EXPECT_THROW(Texture::from_floats(1, 1, 3, {0, NAN, 0}, ColorEncoding::Linear), std::invalid_argument);
}

TEST(LambertMaterial, ReflectsAlbedoOverPiAndConservesEnergy) {
  const Vec3 albedo(0.8f, 0.5f, 0.2f);
  EXPECT_EQ(lambert_f(albedo), albedo * kInvPi);
  // Directional albedo: the integral of f cos over the hemisphere is the albedo. Estimated with
  // uniform sphere directions (pdf 1 / (4 pi)), within 4 standard errors.
  constexpr int kN = 100000;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < kN; ++i) {
    const Vec3 w = sample_uniform_sphere(rand2(i, 6));
    const double x = w.z > 0.0f ? double(lambert_f(albedo).x) * w.z / uniform_sphere_pdf() : 0.0;
    sum += x;
    sum2 += x * x;
  }
  const double mean = sum / kN, error = std::sqrt((sum2 / kN - mean * mean) / kN);
  EXPECT_NEAR(mean, albedo.x, 4.0 * error);
}

TEST(LambertMaterial, TexturedAlbedoComesFromTheTexture) {
  const std::vector<Texture> textures = {Texture::from_bytes(2, 1, 3, {255, 0, 0, 0, 255, 0}, ColorEncoding::Srgb)};
  const Lambert constant{Vec3(0.3f), -1}, textured{Vec3(0.3f), 0};
  EXPECT_EQ(lambert_albedo(constant, textures, Vec2(0.25f, 0.5f)), Vec3(0.3f));
  EXPECT_NEAR(glm::length(lambert_albedo(textured, textures, Vec2(0.25f, 0.5f)) - Vec3(1, 0, 0)), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::length(lambert_albedo(textured, textures, Vec2(0.75f, 0.5f)) - Vec3(0, 1, 0)), 0.0f, 1e-6f);
  const Material m = textured;
  EXPECT_TRUE(std::holds_alternative<Lambert>(m));
}

TEST(Texture, EightBitSrgbIsFilteredBeforeDecodingAsCycles) {
  // A black and a white texel: halfway between them Cycles returns the decoded average of the
  // encoded values, srgb_to_linear(0.5), not the average of the decoded ones (0.5).
  const Texture t = Texture::from_bytes(2, 1, 3, {0, 0, 0, 255, 255, 255}, ColorEncoding::Srgb);
  const glm::vec4 mid = t.lookup(Vec2(0.5f, 0.5f));  // the seam between the two texel centres
  EXPECT_NEAR(mid.x, srgb_to_linear(0.5f), 1e-6f);
  EXPECT_NEAR(mid.y, srgb_to_linear(0.5f), 1e-6f);
  // Texel centres are exact, and decoded.
  EXPECT_NEAR(t.lookup(Vec2(0.25f, 0.5f)).x, 0.0f, 1e-6f);
  EXPECT_NEAR(t.lookup(Vec2(0.75f, 0.5f)).x, 1.0f, 1e-6f);
  EXPECT_NEAR(t.texel(1, 0).x, 1.0f, 1e-6f);
  // Float images are decoded at load and filtered linearly.
  const Texture f = Texture::from_floats(2, 1, 3, {0, 0, 0, 1, 1, 1}, ColorEncoding::Srgb);
  EXPECT_NEAR(f.lookup(Vec2(0.5f, 0.5f)).x, 0.5f, 1e-6f);
}
