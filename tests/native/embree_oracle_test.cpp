// TOYRT against Embree 3 on the same meshes and rays: primary, incoherent (cosine-distributed)
// and shadow rays, on meshes that stress different things. Hit/miss must agree except where
// Embree itself leaks (counted and printed), and t, the triangle and u/v must agree.
#include "oracle_compare.h"

#include <gtest/gtest.h>

#include <cstdio>

using namespace toyrt;
using namespace toyrt::testing;

namespace {

// through: shoot the diffuse rays into the surface (for convex meshes, which outgoing rays miss).
void expect_agreement(BuilderKind builder, const char* name, const MeshData& m, bool through = false, int width = 256,
                      int height = 192) {
  Scene scene;
  scene.add_instance(scene.add_mesh(m.vertices, m.triangles), Mat4(1.0f));
  CommitOptions options;
  options.builder = builder;
  scene.commit(options);
  const EmbreeScene embree(m.vertices, m.triangles);

  const BBox box = bounds_of(m);
  const std::vector<Ray> primary = primary_rays(box, width, height);
  std::vector<Hit> hits;
  for (const Ray& r : primary) hits.push_back(embree.intersect(r));
  const Vec3 light = box.center() + glm::length(box.extent()) * Vec3(-0.4f, -0.9f, 1.3f);
  const std::vector<Ray> diffuse = diffuse_rays(m, primary, hits, 17, through);
  const std::vector<Ray> shadow = shadow_rays(m, primary, hits, light);

  for (auto [kind, rays] : {std::pair{"primary", &primary}, std::pair{"diffuse", &diffuse}}) {
    const Agreement a = compare_with_embree(scene, embree, m, *rays);
    std::printf("[%s %s] %s\n", name, kind, a.summary().c_str());
    EXPECT_EQ(a.toyrt_misses, 0u) << name << " " << kind;
    EXPECT_EQ(a.toyrt_false_hits, 0u) << name << " " << kind;
    EXPECT_EQ(a.t_mismatches, 0u) << name << " " << kind;
    EXPECT_EQ(a.uv_mismatches, 0u) << name << " " << kind;
    EXPECT_EQ(a.occluded_mismatches, 0u) << name << " " << kind;
    // Rounding at boundaries decides rarely: under 0.5 % of the rays.
    EXPECT_LE(a.grazing, a.rays / 200 + 2) << name << " " << kind;
    EXPECT_GT(a.both_hit, a.rays / 1000) << name << " " << kind << ": the rays should see the mesh";
  }
  const OcclusionAgreement o = compare_occlusion_with_embree(scene, embree, m, shadow);
  std::printf("[%s shadow] %s\n", name, o.summary().c_str());
  EXPECT_EQ(o.toyrt_wrong, 0u) << name;
  EXPECT_LE(o.grazing, o.rays / 200 + 2) << name;
}

}  // namespace

// Every test runs once per builder: the LBVH must pass exactly what the SAH BVH passes.
class EmbreeOracle : public ::testing::TestWithParam<BuilderKind> {};
INSTANTIATE_TEST_SUITE_P(Builders, EmbreeOracle, ::testing::Values(BuilderKind::Sah, BuilderKind::Lbvh),
                         [](const ::testing::TestParamInfo<BuilderKind>& info) {
                           return info.param == BuilderKind::Sah ? std::string("Sah") : std::string("Lbvh");
                         });

TEST_P(EmbreeOracle, RandomTriangleSoupAgrees) {
  expect_agreement(GetParam(), "soup", triangle_soup(100000, 0.03f, 1));
}

TEST_P(EmbreeOracle, ClosedSphereAgrees) { expect_agreement(GetParam(), "sphere", uv_sphere(200, 400), true); }

TEST_P(EmbreeOracle, MillionTriangleMeshAgrees) {
  const MeshData m = uv_sphere(708, 708, 1.0f, 0.15f);  // 1,000,872 triangles, bumpy, shared vertices
  ASSERT_GE(m.triangle_count(), 1000000u);
  expect_agreement(GetParam(), "bumpy-1M", m, false, 512, 384);
}

TEST_P(EmbreeOracle, LongThinSliversAgree) { expect_agreement(GetParam(), "slivers", slivers(50000, 2)); }

TEST_P(EmbreeOracle, GeometryFarFromTheOriginAgrees) {
  // A unit-sized object at 1e4 and 1e5, and one of radius 100 at 1e6 (where float spacing is
  // 1/16, a unit object would be a handful of grid points).
  for (auto [distance, radius] : {std::pair{1e4f, 1.0f}, std::pair{1e5f, 1.0f}, std::pair{1e6f, 100.0f}}) {
    const std::string name = "far-" + std::to_string(int(distance));
    const Vec3 offset(distance, -distance, 0.5f * distance);
    expect_agreement(GetParam(), name.c_str(), transformed(uv_sphere(100, 200, 1.0f, 0.2f), radius, offset));
  }
}

TEST_P(EmbreeOracle, TinyScaleAgrees) {
  expect_agreement(GetParam(), "tiny-1e-3", transformed(uv_sphere(100, 200, 1.0f, 0.2f), 1e-3f, Vec3(0.0f)));
  expect_agreement(GetParam(), "tiny-soup", transformed(triangle_soup(20000, 0.03f, 9), 1e-3f, Vec3(2e-3f)));
}
