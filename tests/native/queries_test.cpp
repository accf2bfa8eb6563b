// The exact geometric queries (native/queries/): each crossing of a closed surface counted once
// through shared edges and vertices (convex and star-shaped meshes, whose crossing counts from an
// interior point are known: exactly one), the BVH walks against brute force over all triangles,
// occupancy and distances against closed forms.
#include "queries/block_crossing.h"
#include "queries/closest_point_triangle.h"
#include "queries/crossing_walk.h"
#include "queries/exact_crossing.h"
#include "queries/point_queries.h"
#include "queries/ray_queries.h"
#include "test_scenes.h"

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <tuple>

using namespace toyrt;
using namespace toyrt::testing;

namespace {

// The cube [0, size]^3 + offset, each face split into two triangles along a diagonal, outward.
MeshData cube(float size = 1.0f, const Vec3& offset = Vec3(0.0f)) {
  MeshData m;
  for (int i = 0; i < 8; ++i)
    m.vertices.push_back(offset + size * Vec3(float(i & 1), float((i >> 1) & 1), float((i >> 2) & 1)));
  const uint32_t faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    m.triangles.push_back({f[0], f[1], f[2]});
    m.triangles.push_back({f[0], f[2], f[3]});
  }
  return m;
}

// An icosahedron subdivided `levels` times, vertices pushed onto the sphere of `radius`.
MeshData icosphere(int levels, float radius = 1.0f) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  std::vector<DVec3> v = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                          {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  std::vector<Triangle> f = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                             {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                             {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back(0.5 * (v[a] + v[b]));
      return mid[key] = uint32_t(v.size() - 1);
    };
    std::vector<Triangle> next;
    for (const Triangle& tri : f) {
      const uint32_t a = midpoint(tri.x, tri.y), b = midpoint(tri.y, tri.z), c = midpoint(tri.z, tri.x);
      next.insert(next.end(), {{tri.x, a, c}, {tri.y, b, a}, {tri.z, c, b}, {a, b, c}});
    }
    f = std::move(next);
  }
  MeshData m;
  for (const DVec3& p : v) m.vertices.push_back(Vec3(glm::normalize(p) * double(radius)));
  m.triangles = f;
  return m;
}

struct Committed {
  Scene scene;
  explicit Committed(const MeshData& m, const Mat4& to_world = Mat4(1.0f)) {
    scene.add_instance(scene.add_mesh(m.vertices, m.triangles), to_world);
    scene.commit();
  }
};

std::vector<uint32_t> counts_of(const Scene& scene, const std::vector<Ray>& rays) {
  std::vector<float> org, dir, tnear, tfar;
  for (const Ray& r : rays) {
    org.insert(org.end(), {r.org.x, r.org.y, r.org.z});
    dir.insert(dir.end(), {r.dir.x, r.dir.y, r.dir.z});
    tnear.push_back(r.tnear);
    tfar.push_back(r.tfar);
  }
  std::vector<uint32_t> counts(rays.size());
  queries::count_intersections(scene, RayBatch{org.data(), dir.data(), tnear.data(), 1, tfar.data(), 1, rays.size()},
                               counts.data());
  return counts;
}

// Brute force: the exact test against every triangle, no BVH.
uint32_t brute_force_count(const MeshData& m, const Ray& r) {
  const queries::ExactRay exact{DVec3(r.org), DVec3(r.dir)};
  uint32_t n = 0;
  for (const Triangle& t : m.triangles) {
    queries::Crossing c;
    if (queries::exact_crossing(exact, m.vertices[t.x], m.vertices[t.y], m.vertices[t.z], c))
      n += c.t >= r.tnear && c.t < r.tfar;
  }
  return n;
}

// An independent double-precision oracle for rays far from every edge (Moller-Trumbore in
// double): returns -1 when some triangle's barycentrics come within 1e-9 of an edge, where
// rounding could decide.
int double_oracle_count(const MeshData& m, const Ray& r) {
  int n = 0;
  const DVec3 o(r.org), d(r.dir);
  for (const Triangle& t : m.triangles) {
    const DVec3 a(m.vertices[t.x]), e1 = DVec3(m.vertices[t.y]) - a, e2 = DVec3(m.vertices[t.z]) - a;
    const DVec3 p = glm::cross(d, e2);
    const double det = glm::dot(e1, p);
    if (std::fabs(det) < 1e-12) continue;
    const DVec3 s = o - a, q = glm::cross(s, e1);
    const double u = glm::dot(s, p) / det, v = glm::dot(d, q) / det, tt = glm::dot(e2, q) / det;
    const double margin = std::min({std::fabs(u), std::fabs(v), std::fabs(1.0 - u - v)});
    if (margin < 1e-9 && u > -1e-9 && v > -1e-9 && u + v < 1 + 1e-9) return -1;
    n += u > 0 && v > 0 && u + v < 1 && tt >= r.tnear && tt < r.tfar;
  }
  return n;
}

// From `inside`, rays at every vertex and edge: each must cross a convex or star-shaped (about
// `inside`) closed mesh exactly once, and the line through them exactly twice (convex) or an
// even number of times.
void expect_one_crossing(const char* name, const MeshData& m, const Vec3& inside, bool convex) {
  SCOPED_TRACE(name);
  Committed c(m);
  std::vector<Ray> rays = rays_at_vertices_and_edges(m, inside, 3, 7);
  const std::vector<uint32_t> ahead = counts_of(c.scene, rays);
  size_t wrong = 0, odd_lines = 0;
  for (size_t i = 0; i < rays.size(); ++i) wrong += ahead[i] != 1;
  for (Ray& r : rays) r.tnear = -kInfinity;
  const std::vector<uint32_t> line = counts_of(c.scene, rays);
  for (size_t i = 0; i < rays.size(); ++i) odd_lines += convex ? line[i] != 2 : line[i] % 2 != 0;
  EXPECT_EQ(wrong, 0u) << "of " << rays.size() << " rays";
  EXPECT_EQ(odd_lines, 0u) << "of " << rays.size() << " lines";
}

}  // namespace

TEST(ExactCrossing, SharedEdgeIsCrossedByExactlyOneTriangle) {
  // Two triangles sharing the diagonal (0,0)-(1,1) of a unit quad; rays exactly through it.
  const Vec3 p[4] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  for (float s : {0.0f, 0.25f, 0.5f, 0.75f, 1.0f})
    for (float dz : {-1.0f, 1.0f})
      for (float tilt : {0.0f, 0.5f, -3.0f}) {
        const Vec3 target(s, s, 0.0f), dir(tilt, 0.25f * tilt, dz);
        const queries::ExactRay r{DVec3(target - dir), DVec3(dir)};
        queries::Crossing c;
        const int n =
            int(queries::exact_crossing(r, p[0], p[1], p[2], c)) + queries::exact_crossing(r, p[0], p[2], p[3], c);
        const bool corner = s == 0.0f || s == 1.0f;  // corners (0,0), (1,1) are on the quad's outline
        if (!corner) {
          EXPECT_EQ(n, 1) << "s=" << s << " dz=" << dz << " tilt=" << tilt;
        }
        EXPECT_LE(n, 1);
      }
}

TEST(ExactCrossing, RayInTheTrianglesPlaneNeverCrossesIt) {
  const queries::ExactRay r{DVec3(-1, 0.25, 0), DVec3(1, 0, 0)};
  queries::Crossing c;
  EXPECT_FALSE(queries::exact_crossing(r, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, c));
}

TEST(ExactCrossing, DistanceSignIsExactAtTheOrigin) {
  // The origin exactly on the triangle: t = 0 with sign 0; just off it by one float ulp: t > 0.
  queries::Crossing c;
  ASSERT_TRUE(
      queries::exact_crossing({DVec3(0.25, 0.25, 0.0), DVec3(0.0, 0.0, 1.0)}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, c));
  EXPECT_EQ(c.t_sign, 0);
  EXPECT_EQ(c.t, 0.0);
  const double below = -std::ldexp(1.0, -149);
  ASSERT_TRUE(
      queries::exact_crossing({DVec3(0.25, 0.25, below), DVec3(0.0, 0.0, 1.0)}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, c));
  EXPECT_EQ(c.t_sign, 1);
  EXPECT_GT(c.t, 0.0);
}

TEST(CountIntersections, ConvexMeshesAreCrossedOnceFromInsideThroughEdgesAndVertices) {
  expect_one_crossing("cube", cube(2.0f), Vec3(1.0f), true);
  expect_one_crossing("cube-corner-aimed-off-centre", cube(4.0f), Vec3(1.0f, 2.0f, 3.0f), true);
  expect_one_crossing("cube-at-1e5", cube(2.0f, Vec3(1e5f, -1e5f, 3e5f)), Vec3(1e5f + 1, -1e5f + 1, 3e5f + 1), true);
  expect_one_crossing("cube-tiny", cube(std::ldexp(2.0f, -60)), Vec3(std::ldexp(1.0f, -60)), true);
  expect_one_crossing("icosphere", icosphere(4), Vec3(0.0f), true);
  expect_one_crossing("icosphere-off-centre", icosphere(4), Vec3(0.3f, -0.2f, 0.1f), true);
  expect_one_crossing("icosphere-at-1e4", transformed(icosphere(3), 1.0f, Vec3(1e4f)), Vec3(1e4f), true);
  expect_one_crossing("icosphere-tiny", transformed(icosphere(3), 1e-6f, Vec3(0.0f)), Vec3(0.0f), true);
  expect_one_crossing("uv-sphere-poles", uv_sphere(40, 80), Vec3(0.0f), true);
  expect_one_crossing("bicone-fan", bicone_fan(500), Vec3(0.01f, 0.02f, 0.0f), true);
  // Star-shaped about the centre: one crossing per ray from it, even counts along lines.
  expect_one_crossing("bumpy-sphere", uv_sphere(60, 120, 1.0f, 0.2f), Vec3(0.0f), false);
}

TEST(CountIntersections, InstancedMeshIsExactUnderItsTransform) {
  const MeshData m = icosphere(3);
  Mat4 to_world = glm::scale(glm::rotate(Mat4(1.0f), 0.7f, Vec3(1, 2, 3)), Vec3(2.0f, 0.5f, 1.0f));
  to_world[3] = glm::vec4(10.0f, -3.0f, 2.0f, 1.0f);
  Committed c(m, to_world);
  std::vector<Ray> rays;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  for (int i = 0; i < 5000; ++i) {
    Ray r;
    r.org = Vec3(10.0f, -3.0f, 2.0f);
    r.dir = Vec3(to_world * glm::vec4(m.vertices[size_t(i) % m.vertices.size()], 0.0f)) +
            (i % 2 ? Vec3(0.0f) : 1e-3f * Vec3(unit(rng), unit(rng), unit(rng)));
    rays.push_back(r);
  }
  size_t wrong = 0;
  for (uint32_t n : counts_of(c.scene, rays)) wrong += n != 1;
  EXPECT_EQ(wrong, 0u);
}

TEST(CountIntersections, BvhWalkMatchesBruteForceAndTheDoubleOracle) {
  const MeshData m = uv_sphere(30, 60, 1.0f, 0.3f);
  Committed c(m);
  std::vector<Ray> rays = rays_at_vertices_and_edges(m, Vec3(0.1f, 0.05f, -0.1f), 1, 5);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> unit(-2.0f, 2.0f);
  for (int i = 0; i < 3000; ++i) {
    Ray r;
    r.org = Vec3(unit(rng), unit(rng), unit(rng));
    r.dir = Vec3(unit(rng), unit(rng), unit(rng));
    r.tnear = i % 3 == 0 ? -kInfinity : 0.0f;
    r.tfar = i % 5 == 0 ? 0.5f : kInfinity;
    rays.push_back(r);
  }
  const std::vector<uint32_t> counts = counts_of(c.scene, rays);
  size_t brute_wrong = 0, oracle_wrong = 0, oracle_checked = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    brute_wrong += counts[i] != brute_force_count(m, rays[i]);
    const int oracle = double_oracle_count(m, rays[i]);
    if (oracle < 0) continue;
    ++oracle_checked;
    oracle_wrong += int(counts[i]) != oracle;
  }
  EXPECT_EQ(brute_wrong, 0u);
  EXPECT_EQ(oracle_wrong, 0u);
  EXPECT_GT(oracle_checked, 2000u);  // the oracle decided most rays, so the comparison means something
}

// The interleaved walks (queries/interleaved_walk.h) find, ray by ray, the crossings of the single
// walk: forced on small meshes (threshold 0), with several instances (one identity, one
// transformed), rays at vertices and edges, random rays with finite and infinite segments, and
// invalid rays among them.
TEST(CountIntersections, InterleavedWalksFindTheCrossingsOfTheSingleWalk) {
  Scene scene;
  const MeshData bumpy = uv_sphere(30, 60, 1.0f, 0.3f), ico = icosphere(3), box = cube(2.0f, Vec3(3.0f, 0.0f, 0.0f));
  scene.add_instance(scene.add_mesh(bumpy.vertices, bumpy.triangles), Mat4(1.0f));
  Mat4 to_world = glm::scale(glm::rotate(Mat4(1.0f), 0.7f, Vec3(1, 2, 3)), Vec3(2.0f, 0.5f, 1.0f));
  to_world[3] = glm::vec4(0.5f, -0.3f, 0.2f, 1.0f);
  scene.add_instance(scene.add_mesh(ico.vertices, ico.triangles), to_world);
  scene.add_instance(scene.add_mesh(box.vertices, box.triangles), Mat4(1.0f));
  scene.commit();
  std::vector<Ray> rays = rays_at_vertices_and_edges(bumpy, Vec3(0.1f, 0.05f, -0.1f), 1, 5);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> unit(-3.0f, 3.0f);
  for (int i = 0; i < 4000; ++i) {
    Ray r;
    r.org = Vec3(unit(rng), unit(rng), unit(rng));
    r.dir = i % 97 == 0 ? Vec3(0.0f) : Vec3(unit(rng), unit(rng), unit(rng));
    r.tnear = i % 3 == 0 ? -kInfinity : 0.0f;
    r.tfar = i % 5 == 0 ? 0.5f : kInfinity;
    rays.push_back(r);
  }
  std::vector<float> org, dir, tnear, tfar;
  for (const Ray& r : rays) {
    org.insert(org.end(), {r.org.x, r.org.y, r.org.z});
    dir.insert(dir.end(), {r.dir.x, r.dir.y, r.dir.z});
    tnear.push_back(r.tnear);
    tfar.push_back(r.tfar);
  }
  const RayBatch batch{org.data(), dir.data(), tnear.data(), 1, tfar.data(), 1, rays.size()};
  using Key = std::tuple<uint32_t, uint32_t, double>;  // instance, prim, t
  std::vector<std::vector<Key>> single(rays.size()), interleaved(rays.size());
  for (size_t i = 0; i < rays.size(); ++i)
    queries::for_each_crossing(scene, batch.at(i),
                               [&](uint32_t inst, uint32_t, uint32_t prim, const queries::Crossing& c) {
                                 single[i].emplace_back(inst, prim, c.t);
                               });
  for (size_t begin = 0; begin < rays.size(); begin += 64)  // in tasks of 64 rays, as the batch runs
    queries::for_each_crossing_of_rays(
        scene, batch, begin, std::min(rays.size(), begin + 64),
        [&](uint32_t i, uint32_t inst, uint32_t, uint32_t prim, const queries::Crossing& c) {
          interleaved[i].emplace_back(inst, prim, c.t);
        },
        0);
  size_t differ = 0, crossings = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    std::sort(single[i].begin(), single[i].end());
    std::sort(interleaved[i].begin(), interleaved[i].end());
    differ += single[i] != interleaved[i];
    crossings += single[i].size();
  }
  EXPECT_EQ(differ, 0u);
  EXPECT_GT(crossings, rays.size());  // most rays cross something, so the comparison means something
}

// A mesh large enough for count_intersections and list_intersections to interleave their walks
// (queries/crossing_walk.h: kInterleaveBytes): the counts equal brute force, and the list gives
// each ray brute force's triangles in t order.
TEST(CountIntersections, LargeMeshCountsAndListsMatchBruteForce) {
  const MeshData m = icosphere(6);  // 81,920 triangles, about 5 MB of nodes and blocks
  Committed c(m);
  ASSERT_TRUE(queries::interleaving_pays(c.scene));
  std::vector<Ray> rays;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(-1.5f, 1.5f);
  for (int i = 0; i < 300; ++i) {
    Ray r;
    r.org = Vec3(unit(rng), unit(rng), unit(rng));
    r.dir = i % 4 == 0 ? Vec3(m.vertices[size_t(i) * 97 % m.vertices.size()]) - r.org
                       : Vec3(unit(rng), unit(rng), unit(rng));
    r.tnear = i % 3 == 0 ? -kInfinity : 0.0f;
    rays.push_back(r);
  }
  const std::vector<uint32_t> counts = counts_of(c.scene, rays);
  size_t wrong = 0, total = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    wrong += counts[i] != brute_force_count(m, rays[i]);
    total += counts[i];
  }
  EXPECT_EQ(wrong, 0u);
  EXPECT_GT(total, rays.size() / 2);

  std::vector<float> org, dir, tnear, tfar;
  for (const Ray& r : rays) {
    org.insert(org.end(), {r.org.x, r.org.y, r.org.z});
    dir.insert(dir.end(), {r.dir.x, r.dir.y, r.dir.z});
    tnear.push_back(r.tnear);
    tfar.push_back(r.tfar);
  }
  const RayBatch batch{org.data(), dir.data(), tnear.data(), 1, tfar.data(), 1, rays.size()};
  const queries::HitList hits = queries::list_intersections(c.scene, batch, 1u << 20, 2);
  size_t wrong_lists = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    const queries::ExactRay exact{DVec3(rays[i].org), DVec3(rays[i].dir)};
    std::vector<std::pair<double, int32_t>> expected;  // (t, prim) of brute force, in t order
    for (size_t k = 0; k < m.triangles.size(); ++k) {
      const Triangle& t = m.triangles[k];
      queries::Crossing x;
      if (queries::exact_crossing(exact, m.vertices[t.x], m.vertices[t.y], m.vertices[t.z], x) &&
          x.t >= rays[i].tnear && x.t < rays[i].tfar)
        expected.emplace_back(x.t, int32_t(k));
    }
    std::sort(expected.begin(), expected.end());
    std::vector<int32_t> want, got;
    for (const auto& e : expected) want.push_back(e.second);
    for (int64_t k = hits.offsets[i]; k < hits.offsets[i + 1]; ++k) {
      got.push_back(hits.prim[size_t(k)]);
      wrong_lists += hits.ray[size_t(k)] != i;
    }
    wrong_lists += got != want;
  }
  EXPECT_EQ(wrong_lists, 0u);
}

// The float filter may only drop lanes the exact test rejects: on every block of meshes at the
// origin, far from it and at tiny scales (where float products underflow), for rays aimed at
// vertices and edges and random rays, each lane the exact test crosses is a candidate, and each
// lane whose plane holds the ray's origin (exact zero volume) is left to the on-surface test.
TEST(BlockCrossing, FloatFilterDropsOnlyLanesTheExactTestRejects) {
  ASSERT_TRUE(queries::float_filter_usable());
  const struct {
    const char* name;
    MeshData mesh;
    Vec3 inside;
  } cases[] = {
      {"uv-sphere", uv_sphere(20, 40, 1.0f, 0.3f), Vec3(0.1f, 0.05f, -0.1f)},
      {"cube", cube(2.0f), Vec3(1.0f)},
      {"icosphere-at-1e4", transformed(icosphere(2), 1.0f, Vec3(1e4f)), Vec3(1e4f)},
      {"icosphere-1e-6", transformed(icosphere(2), 1e-6f, Vec3(0.0f)), Vec3(0.0f)},
      {"cube-2^-60", cube(std::ldexp(2.0f, -60)), Vec3(std::ldexp(1.0f, -60))},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    Committed scene(c.mesh);
    const Mesh& mesh = scene.scene.mesh(0);
    std::vector<Ray> rays = rays_at_vertices_and_edges(c.mesh, c.inside, 1, 13);
    // Rays from the mesh's own vertices (origins on the surface: zero volumes), along +x.
    for (const Vec3& v : c.mesh.vertices) {
      Ray r;
      r.org = v;
      r.dir = Vec3(1.0f, 0.0f, 0.0f);
      rays.push_back(r);
    }
    size_t dropped_crossings = 0, dropped_planes = 0, crossings = 0, planes = 0;
    for (const Ray& r : rays) {
      const queries::ExactRay exact{DVec3(r.org), DVec3(r.dir)};
      const queries::FloatFilterRay fr = queries::float_filter_ray(exact);
      for (const TriangleBlock& b : mesh.blocks()) {
        uint32_t on_plane = 0;
        const uint32_t candidates = queries::float_candidates(fr, b, &on_plane);
        for (int lane = 0; lane < kBlockWidth; ++lane) {
          if (b.prim[lane] == kNoTriangle) continue;
          const Vec3 p0 = b.vertex(lane, 0), p1 = b.vertex(lane, 1), p2 = b.vertex(lane, 2);
          queries::Crossing x;
          if (queries::exact_crossing(exact, p0, p1, p2, x)) {
            ++crossings;
            dropped_crossings += !(candidates >> lane & 1);
          }
          if (queries::triple_sign(DVec3(p0) - exact.org, DVec3(p1) - exact.org, DVec3(p2) - exact.org) == 0) {
            ++planes;
            dropped_planes += !(on_plane >> lane & 1);
          }
        }
      }
    }
    EXPECT_EQ(dropped_crossings, 0u) << "of " << crossings;
    EXPECT_EQ(dropped_planes, 0u) << "of " << planes;
    EXPECT_GT(planes, 0u);  // the origins on the surface were tested
  }
}

TEST(ListIntersections, HitsComeInRayAndDistanceOrderWithinTheBound) {
  Committed c(uv_sphere(20, 40, 1.0f, 0.3f));
  std::vector<float> org, dir;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  const size_t n = 500;
  for (size_t i = 0; i < n; ++i) {
    org.insert(org.end(), {-3.0f, 0.5f * unit(rng), 0.5f * unit(rng)});
    dir.insert(dir.end(), {1.0f, 0.1f * unit(rng), 0.1f * unit(rng)});
  }
  const float zero = 0.0f, inf = kInfinity;
  const RayBatch batch{org.data(), dir.data(), &zero, 0, &inf, 0, n};
  std::vector<uint32_t> counts(n);
  queries::count_intersections(c.scene, batch, counts.data());
  const queries::HitList hits = queries::list_intersections(c.scene, batch, 1u << 20);
  ASSERT_EQ(hits.offsets.size(), n + 1);
  for (size_t i = 0; i < n; ++i) {
    ASSERT_EQ(hits.offsets[i + 1] - hits.offsets[i], int64_t(counts[i]));
    EXPECT_EQ(counts[i] % 2, 0u);  // a line from outside through a closed mesh
    for (int64_t k = hits.offsets[i]; k < hits.offsets[i + 1]; ++k) {
      EXPECT_EQ(hits.ray[size_t(k)], i);
      if (k > hits.offsets[i]) {
        EXPECT_LE(hits.t[size_t(k) - 1], hits.t[size_t(k)]);
      }
    }
  }
  EXPECT_THROW(queries::list_intersections(c.scene, batch, hits.size() - 1), std::length_error);
}

TEST(Occupancy, CubeGridPointsAreInsideExactlyWhereTheyLieInTheClosedCube) {
  for (const Vec3 offset : {Vec3(0.0f), Vec3(1e5f, -2e5f, 4e5f)}) {
    Committed c(cube(4.0f, offset));
    std::vector<float> pts;
    std::vector<uint8_t> expected;
    for (int x = -1; x <= 5; ++x)
      for (int y = -1; y <= 5; ++y)
        for (int z = -1; z <= 5; ++z) {
          pts.insert(pts.end(), {offset.x + float(x), offset.y + float(y), offset.z + float(z)});
          expected.push_back(x >= 0 && x <= 4 && y >= 0 && y <= 4 && z >= 0 && z <= 4);
        }
    std::vector<uint8_t> inside(expected.size());
    queries::compute_occupancy(c.scene, pts.data(), expected.size(), inside.data());
    EXPECT_EQ(inside, expected);
  }
}

TEST(Occupancy, PointsOnRaysThroughVerticesAndEdgesOfASphere) {
  // Points at 0.5x and 1.5x the distance to vertices and edge points: inside, outside.
  const MeshData m = icosphere(3);
  Committed c(m);
  std::vector<float> pts;
  std::vector<uint8_t> expected;
  for (const Ray& r : rays_at_vertices_and_edges(m, Vec3(0.0f), 2, 3))
    for (float s : {0.5f, 0.99f, 1.01f, 1.5f}) {
      const Vec3 p = s * r.dir;
      pts.insert(pts.end(), {p.x, p.y, p.z});
      expected.push_back(s < 1.0f);
    }
  std::vector<uint8_t> inside(expected.size());
  queries::compute_occupancy(c.scene, pts.data(), expected.size(), inside.data());
  EXPECT_EQ(inside, expected);
}

// Under flush-to-zero (a caller's MXCSR) the float filter is off, and occupancy takes the separate
// on-surface walk (queries/point_walk.h over the mesh's wide tree) before the parity: the same
// answers, on a mesh that is a single leaf (the cube) and on one with wide nodes (the sphere,
// whose vertices lie on the surface exactly).
TEST(Occupancy, FlushToZeroGivesTheSameAnswersThroughTheOnSurfaceWalk) {
  for (const MeshData& m : {cube(4.0f, Vec3(-2.0f)), icosphere(3)}) {
    Committed c(m);
    std::vector<float> pts;
    std::vector<uint8_t> expected;  // both meshes are star-shaped about the origin
    for (const Vec3& v : m.vertices)
      for (float s : {0.5f, 1.0f, 1.5f}) {
        pts.insert(pts.end(), {s * v.x, s * v.y, s * v.z});
        expected.push_back(s <= 1.0f);  // inside, or on the surface at the vertex itself
      }
    std::vector<uint8_t> inside(expected.size());
    const unsigned csr = _mm_getcsr();
    _mm_setcsr(csr | 0x8040u);  // FTZ and DAZ, on this thread, which runs a one-thread query
    const bool usable = queries::float_filter_usable();
    queries::compute_occupancy(c.scene, pts.data(), expected.size(), inside.data(), 1);
    _mm_setcsr(csr);
    EXPECT_FALSE(usable);
    EXPECT_EQ(inside, expected);
  }
}

TEST(ClosestPoints, CubeDistancesHaveClosedForms) {
  Committed c(cube(2.0f));
  const std::vector<float> pts = {1, 1, 1, 5, 1, 1, 4, 4, 4, 1, 1, 2, -1, 3, 1};
  const float want[] = {-1.0f, 3.0f, 2.0f * std::sqrt(3.0f), 0.0f, std::sqrt(2.0f)};
  std::vector<float> d(5);
  queries::compute_distance(c.scene, pts.data(), 5, d.data(), true);
  for (int i = 0; i < 5; ++i) EXPECT_FLOAT_EQ(d[size_t(i)], want[i]) << i;
}

TEST(ClosestPoints, BvhSearchMatchesBruteForceOnASphere) {
  const MeshData m = icosphere(4, 2.0f);
  Mat4 to_world = glm::rotate(Mat4(1.0f), 0.3f, Vec3(0, 1, 1));
  to_world[3] = glm::vec4(1.0f, 2.0f, 3.0f, 1.0f);
  Committed c(m, to_world);
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> unit(-4.0f, 4.0f);
  const size_t n = 2000;
  std::vector<float> pts;
  for (size_t i = 0; i < 3 * n; ++i) pts.push_back(unit(rng) + (i % 3 == 0 ? 1.0f : i % 3 == 1 ? 2.0f : 3.0f));
  std::vector<float> cp(3 * n), dist(n), u(n), v(n), normal(3 * n);
  std::vector<int32_t> mesh(n), inst(n), prim(n);
  queries::compute_closest_points(
      c.scene, pts.data(), n,
      {cp.data(), dist.data(), mesh.data(), inst.data(), prim.data(), u.data(), v.data(), normal.data()});
  const glm::dmat4 mw(to_world);
  size_t wrong = 0;
  for (size_t i = 0; i < n; ++i) {
    const DVec3 q(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]);
    double best = INFINITY;
    for (const Triangle& t : m.triangles) {
      auto w = [&](uint32_t k) { return DVec3(mw * glm::dvec4(DVec3(m.vertices[k]), 1.0)); };
      const DVec3 p = queries::closest_on_triangle(q, w(t.x), w(t.y), w(t.z)).point;
      best = std::min(best, glm::length(q - p));
    }
    wrong += dist[i] != float(best);
    EXPECT_EQ(inst[i], 0);
  }
  EXPECT_EQ(wrong, 0u);
}

TEST(PointQueries, NonFinitePointsAreRefusedAndEmptySceneAnswersNothing) {
  Committed c(cube());
  const float bad[3] = {0.0f, NAN, 0.0f};
  uint8_t inside;
  float d;
  EXPECT_THROW(queries::compute_occupancy(c.scene, bad, 1, &inside), std::invalid_argument);
  EXPECT_THROW(queries::compute_distance(c.scene, bad, 1, &d, false), std::invalid_argument);
  Scene empty;
  empty.commit();
  const float p[3] = {0.0f, 0.0f, 0.0f};
  queries::compute_distance(empty, p, 1, &d, true);
  EXPECT_EQ(d, kInfinity);
  queries::compute_occupancy(empty, p, 1, &inside);
  EXPECT_EQ(inside, 0);
}
