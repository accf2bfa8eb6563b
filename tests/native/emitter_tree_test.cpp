// Emissive triangles chosen through the light tree (lights/mesh_emitters.h from kEmitterTreeFrom
// triangles on): the probabilities of all triangles sum to one from points all around; select()
// returns what probability() recomputes bit for bit, and sample_emitters()'s density is
// emitter_pdf()'s for the same direction (what MIS with the cosine ray needs); a one-sided
// emitter's triangles facing away are never picked; the one-sample estimate through the tree
// converges to the closed-form irradiance of a square tiled into 3,200 triangles; and the scene
// builds the tree at commit only for many triangles spread over much of it.
#include "lights/light_tree.h"
#include "lights/mesh_emitters.h"
#include "render/renderer.h"
#include "sampling/rng.h"

#include "light_estimates.h"
#include "render_fixtures.h"
#include "test_scenes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace toyrt;
using namespace toyrt::testing;

namespace {

EmissiveTriangle triangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& radiance,
                          EmitterSides sides = EmitterSides::Both) {
  EmissiveTriangle t;
  t.p0 = a;
  t.e1 = b - a;
  t.e2 = c - a;
  const Vec3 n = glm::cross(t.e1, t.e2);
  t.area = 0.5f * glm::length(n);
  t.normal = n / (2.0f * t.area);
  t.radiance = radiance;
  t.sides = sides;
  return t;
}

// A side x side grid of quads (two triangles each) over [-size/2, size/2]^2 at height z, normals
// down (towards z = 0) unless `up`.
void add_grid(MeshEmitters& e, int side, float size, float z, const Vec3& radiance, EmitterSides sides,
              bool up = false) {
  const float cell = size / float(side);
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j) {
      const Vec3 a(-0.5f * size + float(i) * cell, -0.5f * size + float(j) * cell, z);
      const Vec3 b = a + Vec3(cell, 0, 0), c = a + Vec3(cell, cell, 0), d = a + Vec3(0, cell, 0);
      if (up) {
        e.add(triangle(a, b, c, radiance, sides));
        e.add(triangle(a, c, d, radiance, sides));
      } else {
        e.add(triangle(a, c, b, radiance, sides));
        e.add(triangle(a, d, c, radiance, sides));
      }
    }
}

// 2,000 triangles of random size, orientation, radiance and sides in a 20 m box.
MeshEmitters scattered(uint32_t seed) {
  MeshEmitters e;
  for (uint32_t i = 0; i < 2000; ++i) {
    const auto r = [&](uint32_t d) { return random_float(i, 0, d, seed); };
    const Vec3 a(20.0f * r(0) - 10.0f, 20.0f * r(1) - 10.0f, 6.0f * r(2) - 2.0f);
    const float s = 0.05f + 0.5f * r(3);
    const Vec3 b = a + s * Vec3(r(4) - 0.5f, r(5) - 0.5f, r(6) - 0.5f);
    const Vec3 c = a + s * Vec3(r(7) - 0.5f, r(8) - 0.5f, r(9) - 0.5f);
    const EmitterSides sides = i % 3 == 0 ? EmitterSides::Front : i % 3 == 1 ? EmitterSides::Back : EmitterSides::Both;
    e.add(triangle(a, b, c, Vec3(1.0f + 50.0f * r(10) * r(10)), sides));
  }
  e.finish();
  return e;
}

Vec3 point(uint32_t j, uint32_t seed) {
  return {24.0f * random_float(j, 1, 0, seed) - 12.0f, 24.0f * random_float(j, 1, 1, seed) - 12.0f,
          8.0f * random_float(j, 1, 2, seed) - 3.0f};
}
Vec3 normal(uint32_t j, uint32_t seed) {
  return glm::normalize(Vec3(2.0f * random_float(j, 1, 3, seed) - 1.0f, 2.0f * random_float(j, 1, 4, seed) - 1.0f,
                             2.0f * random_float(j, 1, 5, seed) - 0.9f));
}

}  // namespace

TEST(EmitterTree, ProbabilitiesOfAllTrianglesSumToOneFromPointsAllAround) {
  // Two-sided triangles and no receiver cosine: no cluster's bound can fail (theta_o + theta_e =
  // pi), so no branch is a dead end and the sum is one wherever p is.
  MeshEmitters e;
  for (uint32_t i = 0; i < 1500; ++i) {
    const auto r = [&](uint32_t d) { return random_float(i, 0, d, 21); };
    const Vec3 a(20.0f * r(0) - 10.0f, 20.0f * r(1) - 10.0f, 6.0f * r(2) - 2.0f);
    e.add(triangle(a, a + Vec3(0.3f * r(3) + 0.01f, 0.0f, 0.1f * r(4)),
                   a + Vec3(0.0f, 0.3f * r(5) + 0.01f, 0.2f * r(6)), Vec3(1.0f + 10.0f * r(7))));
  }
  e.finish();
  ASSERT_TRUE(e.uses_tree());
  for (uint32_t j = 0; j < 12; ++j) {
    const Vec3 p = point(j, 22);
    double sum = 0.0;
    for (size_t i = 0; i < e.triangles.size(); ++i) sum += emitter_probability(e, p, Vec3(0.0f), i);
    EXPECT_NEAR(sum, 1.0, 1e-5) << j;
  }
}

TEST(EmitterTree, SelectMatchesProbabilityBitForBitAndSampleDensitiesAreEmitterPdf) {
  const MeshEmitters e = scattered(23);
  ASSERT_TRUE(e.uses_tree());
  constexpr int kN = 30000;
  for (uint32_t j = 0; j < 8; ++j) {
    const Vec3 p = point(j, 24), n = normal(j, 24);
    double sum = 0.0;
    std::vector<double> expected(e.triangles.size());
    for (size_t i = 0; i < e.triangles.size(); ++i) sum += expected[i] = emitter_probability(e, p, n, i);
    EXPECT_LE(sum, 1.0 + 1e-5);
    EXPECT_GT(sum, 0.5);  // dead ends (a bound passes, both children fail) are rare
    std::vector<double> counts(e.triangles.size(), 0.0);
    int checked = 0;
    for (uint32_t k = 0; k < uint32_t(kN); ++k) {
      const Vec2 u = rand2(k, 25 + j);
      const LightSelection pick = e.tree.select(e.triangles.data(), p, n, u.x);
      if (!pick.found()) continue;
      ASSERT_EQ(pick.probability, emitter_probability(e, p, n, size_t(pick.index)));  // the same floats
      counts[size_t(pick.index)] += 1.0;
      // sample_emitters() makes the same pick from the same u, and its density is emitter_pdf()'s.
      const LightSample s = sample_emitters(e, p, n, u);
      if (!s.valid()) continue;
      const float pdf = emitter_pdf(e, p, n, size_t(pick.index), s.wi, s.distance);
      ASSERT_NEAR(pdf, s.pdf, 2e-3f * s.pdf) << pick.index;
      ++checked;
    }
    EXPECT_GT(checked, kN / 4);
    for (size_t i = 0; i < e.triangles.size(); ++i)
      EXPECT_NEAR(counts[i], kN * expected[i], 6.0 * std::sqrt(kN * expected[i] * (1.0 - expected[i])) + 1.0) << i;
  }
}

TEST(EmitterTree, TrianglesFacingAwayOnAOneSidedEmitterAreNeverPicked) {
  // A grid at z = 1 emitting only downwards (Front, normals down) and one at z = -1 emitting only
  // downwards too: from points between them, facing any way, the lower grid faces away.
  MeshEmitters e;
  add_grid(e, 20, 4.0f, 1.0f, Vec3(2.0f), EmitterSides::Front);
  add_grid(e, 20, 4.0f, -1.0f, Vec3(2.0f), EmitterSides::Front);
  e.finish();
  ASSERT_TRUE(e.uses_tree());
  const size_t half = e.triangles.size() / 2;
  for (uint32_t j = 0; j < 10; ++j) {
    const Vec3 p(4.0f * random_float(j, 0, 0, 26) - 2.0f, 4.0f * random_float(j, 0, 1, 26) - 2.0f,
                 1.8f * random_float(j, 0, 2, 26) - 0.9f);
    for (const Vec3& n : {Vec3(0.0f), normal(j, 27)}) {
      double upper = 0.0;
      for (size_t i = 0; i < e.triangles.size(); ++i) {
        const float probability = emitter_probability(e, p, n, i);
        if (i >= half)
          EXPECT_EQ(probability, 0.0f) << i;
        else
          upper += probability;
      }
      if (n == Vec3(0.0f)) {
        EXPECT_NEAR(upper, 1.0, 1e-5);
      }
      for (uint32_t k = 0; k < 2000; ++k) {
        const LightSelection pick = e.tree.select(e.triangles.data(), p, n, random_float(k, j, 0, 28));
        if (pick.found()) {
          ASSERT_LT(size_t(pick.index), half);
        }
      }
    }
  }
}

// The irradiance at a point h below a corner of a w x l rectangle of radiance L facing it,
// parallel to its plane: pi L times the form factor (Howell's catalogue, C-11).
double corner_rectangle_irradiance(double L, double w, double l, double h) {
  const double x = w / h, y = l / h;
  return L / 2.0 *
         (x / std::sqrt(1 + x * x) * std::atan(y / std::sqrt(1 + x * x)) +
          y / std::sqrt(1 + y * y) * std::atan(x / std::sqrt(1 + y * y)));
}

TEST(EmitterTree, ASquareTiledIntoThreeThousandTrianglesHasTheWholeSquaresClosedFormIrradiance) {
  // A 1 m square 0.5 m up, facing down (one-sided and two-sided), as 40 x 40 quads: through the
  // tree the one-sample estimate L cos / pdf at points under it converges to the closed form of
  // the whole square (four corner rectangles around the point).
  constexpr float kHeight = 0.5f;
  constexpr double kL = 3.0;
  for (EmitterSides sides : {EmitterSides::Front, EmitterSides::Both}) {
    MeshEmitters e;
    add_grid(e, 40, 1.0f, kHeight, Vec3(float(kL)), sides);
    e.finish();
    ASSERT_TRUE(e.uses_tree());
    const Vec3 up(0, 0, 1);
    for (const Vec3& p : {Vec3(0.0f), Vec3(0.3f, -0.2f, 0.0f), Vec3(0.8f, 0.1f, 0.0f)}) {
      double closed = 0.0;
      // Outside the square (x > 0.5) a corner rectangle counts negatively: the signed widths do it.
      for (double w : {0.5 - double(p.x), 0.5 + double(p.x)})
        for (double l : {0.5 - double(p.y), 0.5 + double(p.y)})
          closed += (w < 0 ? -1.0 : 1.0) * (l < 0 ? -1.0 : 1.0) *
                    corner_rectangle_irradiance(kL, std::fabs(w), std::fabs(l), kHeight);
      const Estimate est = monte_carlo(60000, [&](uint32_t k) {
        const LightSample s = sample_emitters(e, p, up, rand2(k, 29));
        if (!s.valid()) return 0.0;
        return double(s.radiance.x) * std::max(0.0f, glm::dot(up, s.wi)) / double(s.pdf);
      });
      EXPECT_NEAR(est.mean, closed, 4.0 * est.standard_error + 1e-3 * closed) << p.x << " " << est.standard_error;
    }
  }
}

TEST(EmitterTree, ItsVarianceUnderOneCornerOfALargeEmitterIsFarBelowThePowerCdfs) {
  // A 20 m ceiling of 80 x 80 quads 1 m up: from a floor point, the CDF picks triangles 10 m away
  // as often as the ones overhead; the tree picks mostly the ones that light the point.
  MeshEmitters cdf, tree;
  add_grid(cdf, 80, 20.0f, 1.0f, Vec3(1.0f), EmitterSides::Front);
  add_grid(tree, 80, 20.0f, 1.0f, Vec3(1.0f), EmitterSides::Front);
  cdf.finish(SIZE_MAX);
  tree.finish();
  ASSERT_FALSE(cdf.uses_tree());
  ASSERT_TRUE(tree.uses_tree());
  const Vec3 p(-7.0f, 3.0f, 0.0f), up(0, 0, 1);
  const auto estimate = [&](const MeshEmitters& e) {
    return monte_carlo(40000, [&](uint32_t k) {
      const LightSample s = sample_emitters(e, p, up, rand2(k, 30));
      return s.valid() ? double(s.radiance.x) * std::max(0.0f, glm::dot(up, s.wi)) / double(s.pdf) : 0.0;
    });
  };
  const Estimate a = estimate(cdf), b = estimate(tree);
  EXPECT_NEAR(a.mean, b.mean, 4.0 * std::hypot(a.standard_error, b.standard_error));
  RecordProperty("variance_ratio", std::to_string(std::pow(a.standard_error / b.standard_error, 2)));
  EXPECT_LT(b.standard_error * 3.0, a.standard_error) << a.standard_error << " " << b.standard_error;
}

// A square emitter of half-width `half` centred at (x, 0, z), tiled into side x side quads.
void add_emissive_square(Scene& scene, int side, float x, float z, float half, int32_t material) {
  const GridData g = square_grid(side, x, z, half);
  MeshShading sh;
  sh.material_ids.assign(g.mesh.triangles.size(), material);
  scene.add_instance(scene.add_mesh(g.mesh.vertices, g.mesh.triangles, sh), Mat4(1.0f));
}

TEST(EmitterTree, TheSceneBuildsItAtCommitForManySpreadTrianglesAndTheRenderKeepsItsMean) {
  // One emissive square beside the pixel over the 20 m Lambert floor, as 2 triangles (the CDF)
  // and as 8 x 8 quads (128 triangles) through the tree: the same light, so the same pixel within
  // the noise (both strategies, the shadow ray and the cosine ray, weighted by emitter_pdf()). By
  // default the tiled square keeps the CDF: it spans less than kEmitterTreeSpread of the scene.
  double pixel[2];
  for (int tiled = 0; tiled < 2; ++tiled) {
    Scene scene = floor_of(Lambert{Vec3(0.5f), -1});
    MaterialEmission glow;
    glow.radiance = Vec3(5.0f);
    const uint32_t lamp = scene.add_material(Lambert{Vec3(0.0f), -1}, glow);
    add_emissive_square(scene, tiled ? 8 : 1, 0.7f, 0.4f, 0.4f, int32_t(lamp));
    scene.commit();
    EXPECT_EQ(scene.commit_stats().emissive_triangles, tiled ? 128u : 2u);
    EXPECT_EQ(scene.commit_stats().emitter_tree_nodes, 0u);  // few, or compact
    if (tiled) {
      scene.set_emitter_tree_from(kEmitterTreeFrom, 0.0f);
      scene.commit();
      EXPECT_GT(scene.commit_stats().emitter_tree_nodes, 0u);
    }
    pixel[tiled] = render(scene, pixel_above(1e-3f), few_samples(16384)).rgba[0];
  }
  EXPECT_GT(pixel[0], 0.0);
  EXPECT_NEAR(pixel[1], pixel[0], 0.015 * pixel[0]);
  // A 16 m square (a 22.6 m diagonal of the floor's 28.3 m), from the threshold on:
  // the tree by default; fewer triangles: the CDF.
  for (int side : {2, 8}) {
    Scene scene = floor_of(Lambert{Vec3(0.5f), -1});
    MaterialEmission glow;
    glow.radiance = Vec3(5.0f);
    add_emissive_square(scene, side, 0.0f, 2.0f, 8.0f, int32_t(scene.add_material(Lambert{Vec3(0.0f), -1}, glow)));
    scene.commit();
    EXPECT_EQ(scene.commit_stats().emitter_tree_nodes > 0, 2u * side * side >= kEmitterTreeFrom) << side;
  }
  Scene dark = floor_of(Lambert{Vec3(0.5f), -1});
  dark.commit();
  EXPECT_EQ(dark.commit_stats().emitter_tree_nodes, 0u);
  EXPECT_EQ(dark.emitters().memory_bytes(), 0u);
}
