// The GGX albedo tables (sampling/ggx_albedo.h): the committed numbers are what their estimators
// give (a stale file after a change to the lobe fails here: run `make tables`), they agree with
// Cycles' own tables, which were computed independently by Monte Carlo from Cycles' lobe, and the
// lookups interpolate and clamp as Cycles' do.
#include "sampling/ggx_albedo.h"
#include "materials/fresnel.h"

#include <gtest/gtest.h>

#include <cmath>

namespace toyrt {
namespace {

#include "sampling/ggx_albedo_tables.inc"

TEST(GgxAlbedo, CommittedTablesHoldTheirEstimators) {
  constexpr int na = kGgxAlbedoSize, ns = kGgxFresnelBlendSize;
  // Corners, the middle and a few arbitrary entries of each table.
  for (const auto& [x, y] : {std::pair{0, 0}, {31, 31}, {31, 0}, {0, 31}, {16, 9}, {5, 27}, {23, 2}}) {
    const float rough = ggx_table_roughness(x, na), mu = ggx_table_cos(y, na);
    EXPECT_NEAR(kGgxE[y * na + x], estimate_ggx_albedo(rough, mu, kGgxAlbedoSamples), 2e-6) << x << " " << y;
  }
  for (const int x : {0, 13, 31})
    EXPECT_NEAR(kGgxEAvg[x], estimate_ggx_average_albedo(ggx_table_roughness(x, na), kGgxAverageSamples), 2e-6) << x;
  for (const auto& [x, y, z] : {std::tuple{0, 0, 0}, {15, 15, 15}, {15, 0, 8}, {7, 3, 11}, {12, 14, 1}}) {
    const float v = kGgxS[(z * ns + y) * ns + x];
    EXPECT_NEAR(v,
                estimate_ggx_fresnel_blend(ggx_table_roughness(x, ns), ggx_table_cos(y, ns), ggx_table_ior(z, ns),
                                           kGgxBlendSamples),
                2e-6)
        << x << " " << y << " " << z;
  }
}

TEST(GgxAlbedo, AgreesWithCyclesTables) {
  // Entries of Cycles 4.0+'s tables (src/scene/shader.tables: table_ggx_E, table_ggx_Eavg,
  // table_ggx_gen_schlick_ior_s; Monte Carlo with 2^20-2^26 samples per entry), read at the grid
  // points where no interpolation enters.
  struct E2 {
    int x, y;
    float e;
  };
  for (const E2& t : {E2{31, 31, 0.306853f},
                      {16, 31, 0.903873f},
                      {24, 31, 0.592102f},
                      {31, 16, 0.443841f},
                      {24, 8, 0.727744f},
                      {31, 3, 0.765057f},
                      {16, 3, 0.893246f}})
    EXPECT_NEAR(ggx_albedo(t.x / 31.0f, t.y / 31.0f), t.e, 2e-3) << t.x << " " << t.y;
  struct E1 {
    int x;
    float e;
  };
  for (const E1& t : {E1{0, 1.0f}, {8, 0.985805f}, {16, 0.870874f}, {24, 0.631068f}, {31, 0.409137f}})
    EXPECT_NEAR(ggx_average_albedo(t.x / 31.0f), t.e, 3e-3) << t.x;  // 8: 0.98377, a midpoint rule in cos_o
  struct E3 {
    int x, y, z;
    float s;
  };
  for (const E3& t : {E3{15, 15, 4, 0.000366f},
                      {8, 8, 8, 0.037176f},
                      {15, 2, 10, 0.029883f},
                      {4, 12, 6, 0.003853f},
                      {0, 15, 15, 0.0f},
                      {12, 4, 3, 0.011738f},
                      {15, 0, 8, 0.057074f}})
    EXPECT_NEAR(ggx_fresnel_blend(t.x / 15.0f, t.y / 15.0f, ggx_table_ior(t.z, 16)), t.s, 2e-3)
        << t.x << " " << t.y << " " << t.z;
}

TEST(GgxAlbedo, LookupsInterpolateLinearlyAndClampTheAxes) {
  const float a = ggx_albedo(4.0f / 31.0f, 10.0f / 31.0f), b = ggx_albedo(5.0f / 31.0f, 10.0f / 31.0f);
  EXPECT_NEAR(ggx_albedo(4.5f / 31.0f, 10.0f / 31.0f), 0.5f * (a + b), 1e-6f);
  EXPECT_EQ(ggx_albedo(1.5f, 2.0f), ggx_albedo(1.0f, 1.0f));
  EXPECT_EQ(ggx_albedo(-1.0f, NAN), ggx_albedo(0.0f, 0.0f));
  EXPECT_EQ(ggx_average_albedo(NAN), ggx_average_albedo(0.0f));
  // An index below 1 reads as its inverse (the same interface from the other side).
  EXPECT_EQ(ggx_fresnel_blend(0.3f, 0.4f, 1.0f / 1.5f), ggx_fresnel_blend(0.3f, 0.4f, 1.5f));
  EXPECT_TRUE(std::isfinite(ggx_fresnel_blend(0.3f, 0.4f, 0.0f)));
}

TEST(GgxAlbedo, AlbedoIsAnEnergyAndAveragesToItsMean) {
  constexpr int na = kGgxAlbedoSize;
  for (int x = 0; x < na; ++x) {
    // E in (0, 1], and E_avg = 2 int E(mu) mu dmu by the trapezoid rule over the table's rows.
    double avg = 0.0;
    for (int y = 0; y < na; ++y) {
      const float e = kGgxE[y * na + x];
      EXPECT_GT(e, 0.0f);
      EXPECT_LE(e, 1.0f + 1e-6f);
      const double w = (y == 0 || y == na - 1) ? 0.5 : 1.0;
      avg += w * 2.0 * e * (double(y) / (na - 1));
    }
    avg /= (na - 1);
    EXPECT_NEAR(kGgxEAvg[x], avg, 5e-3) << x;
  }
}

TEST(GgxAlbedo, SmoothInterfaceBlendIsTheFresnelCurve) {
  // At the smallest roughness every visible normal is the macro normal: s is the remapped Fresnel
  // curve of the outgoing angle itself.
  for (const float ior : {1.2f, 1.5f, 2.4f})
    for (const float mu : {0.1f, 0.5f, 0.9f}) {
      const float f0 = f0_from_ior(ior);
      const double expected = (fresnel_dielectric(mu, ior) - f0) / (1.0f - f0);
      EXPECT_NEAR(estimate_ggx_fresnel_blend(0.0f, mu, ior, 64), expected, 1e-4) << ior << " " << mu;
    }
}

TEST(GgxAlbedo, FresnelAverageMatchesAFineIntegral) {
  for (const float eta : {1.05f, 1.33f, 1.5f, 2.5f, 1.0f / 1.5f}) {
    double fine = 0.0;
    constexpr int kN = 1 << 16;
    for (int i = 0; i < kN; ++i) {
      const double mu = (i + 0.5) / kN;
      fine += fresnel_dielectric(float(mu), eta) * mu;
    }
    EXPECT_NEAR(fresnel_dielectric_average(eta), 2.0 * fine / kN, 1e-4) << eta;
  }
}

}  // namespace
}  // namespace toyrt
