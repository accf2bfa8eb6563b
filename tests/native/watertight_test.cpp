// Watertightness: from a point inside a closed mesh, rays aimed exactly at vertices, edge
// midpoints and random points on edges must all hit. TOYRT must show zero misses; Embree's
// default and robust modes are run on the same rays and their leaks printed for the record.
#include "oracle_compare.h"

#include <gtest/gtest.h>

#include <cstdio>

using namespace toyrt;
using namespace toyrt::testing;

namespace {

void expect_watertight(BuilderKind builder, const char* name, const MeshData& m, const Vec3& inside, int per_edge = 4) {
  Scene scene;
  scene.add_instance(scene.add_mesh(m.vertices, m.triangles), Mat4(1.0f));
  CommitOptions options;
  options.builder = builder;
  scene.commit(options);
  const std::vector<Ray> rays = rays_at_vertices_and_edges(m, inside, per_edge, 99);
  size_t misses = 0, unoccluded = 0;
  for (const Ray& r : rays) {
    misses += !scene.intersect(r).found();
    unoccluded += !scene.occluded(r);
  }
  const EmbreeScene fast(m.vertices, m.triangles, false), robust(m.vertices, m.triangles, true);
  size_t fast_leaks = 0, robust_leaks = 0;
  for (const Ray& r : rays) {
    fast_leaks += !fast.intersect(r).found();
    robust_leaks += !robust.intersect(r).found();
  }
  std::printf(
      "[%s] %zu rays at vertices and edges: TOYRT %zu misses, Embree default %zu (%.3f %%), Embree robust %zu (%.4f "
      "%%)\n",
      name, rays.size(), misses, fast_leaks, 100.0 * fast_leaks / rays.size(), robust_leaks,
      100.0 * robust_leaks / rays.size());
  EXPECT_EQ(misses, 0u) << name;
  EXPECT_EQ(unoccluded, 0u) << name;
}

}  // namespace

// Every test runs once per builder: the LBVH must pass exactly what the SAH BVH passes.
class Watertight : public ::testing::TestWithParam<BuilderKind> {};
INSTANTIATE_TEST_SUITE_P(Builders, Watertight, ::testing::Values(BuilderKind::Sah, BuilderKind::Lbvh),
                         [](const ::testing::TestParamInfo<BuilderKind>& info) {
                           return info.param == BuilderKind::Sah ? std::string("Sah") : std::string("Lbvh");
                         });

TEST_P(Watertight, SphereHasNoGapsAtEdgesOrVertices) {
  expect_watertight(GetParam(), "sphere", uv_sphere(100, 200), Vec3(0.0f));
  expect_watertight(GetParam(), "sphere-off-centre", uv_sphere(100, 200), Vec3(0.3f, -0.2f, 0.1f));
}

TEST_P(Watertight, FanOfThousandsSharingOneVertexHasNoGaps) {
  // 2 apexes, each shared by 5000 triangles: rays at the apex meet 5000 candidate triangles.
  // Every sliver's box holds the centre the rays start from, so each of the 55,000 rays tests
  // thousands of triangles: 2 random points per edge (beside its midpoint) keep this the suite's
  // longest test at about 10 s, where 8 took 27 s (2 minutes under the sanitizers).
  expect_watertight(GetParam(), "bicone-fan", bicone_fan(5000), Vec3(0.01f, 0.02f, 0.0f), 2);
}

TEST_P(Watertight, BumpyMeshHasNoGaps) {
  expect_watertight(GetParam(), "bumpy", uv_sphere(150, 300, 1.0f, 0.2f), Vec3(0.05f));
}

TEST_P(Watertight, HoldsFarFromTheOriginAndAtTinyScale) {
  for (float d : {1e3f, 1e5f, 1e6f}) {
    const Vec3 offset(d, -0.5f * d, 0.25f * d);
    expect_watertight(GetParam(), ("far-" + std::to_string(int(d))).c_str(),
                      transformed(uv_sphere(60, 120), 1.0f, offset), offset);
  }
  expect_watertight(GetParam(), "tiny-1e-3", transformed(uv_sphere(60, 120), 1e-3f, Vec3(0.0f)), Vec3(0.0f));
  expect_watertight(GetParam(), "tiny-1e-6", transformed(uv_sphere(60, 120), 1e-6f, Vec3(1e-6f)), Vec3(1e-6f));
}

TEST_P(Watertight, HoldsThroughAnInstanceTransform) {
  const MeshData m = uv_sphere(60, 120);
  Scene scene;
  const uint32_t id = scene.add_mesh(m.vertices, m.triangles);
  Mat4 x(1.0f);
  x[0] = glm::vec4(0.8f, 0.3f, 0.0f, 0.0f);
  x[1] = glm::vec4(-0.2f, 1.7f, 0.1f, 0.0f);
  x[2] = glm::vec4(0.0f, 0.4f, 0.6f, 0.0f);
  x[3] = glm::vec4(5.0f, -3.0f, 2.0f, 1.0f);
  scene.add_instance(id, x);
  scene.add_instance(id, glm::mat4(1.0f));  // a second one, so the top level is walked
  CommitOptions options;
  options.builder = GetParam();
  scene.commit(options);
  const Vec3 centre(x[3]);
  size_t misses = 0, rays = 0;
  for (Ray r : rays_at_vertices_and_edges(transformed(m, 1.0f, Vec3(0.0f)), Vec3(0.0f), 2, 5)) {
    // Aim in object space at the vertex or edge point, from the world-space image of the centre.
    r.org = centre;
    r.dir = glm::mat3(x) * r.dir;
    ++rays;
    const Hit h = scene.intersect(r);
    misses += !(h.found() && h.instance == 0);
  }
  std::printf("[instanced] %zu rays, %zu misses\n", rays, misses);
  EXPECT_EQ(misses, 0u);
}
