// The LBVH builder: the OpenCL kernels equal the CPU reference node for node, the tree keeps the
// structural invariants on easy and hard inputs (coincident centroids: duplicate Morton codes),
// and when OpenCL cannot run the scene falls back to the SAH builder with one warning.
// (Hit-level agreement with Embree and watertightness: embree_oracle_test and watertight_test
// run every case with both builders.)
#include "accel/lbvh_builder.h"
#include "accel/wide_bvh.h"
#include "geometry/triangle_block.h"
#include "opencl/device.h"
#include "scene/scene.h"
#include "test_scenes.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>

using namespace toyrt;
using namespace toyrt::testing;

namespace {

using Prims = PrimitiveBounds;
PrimitiveBounds prims_of(const MeshData& m) { return triangle_bounds(m); }

MeshData copies_of_one_triangle(size_t n) {
  MeshData m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.triangles.assign(n, Triangle(0, 1, 2));
  return m;
}

MeshData first_triangles(const MeshData& m, size_t n) {
  MeshData out = m;
  out.triangles.resize(n);
  return out;
}

void expect_same_as_reference(const MeshData& m, MortonBits bits) {
  const Prims p = prims_of(m);
  const LbvhConfig config{bits};
  const LbvhHierarchy gpu = build_lbvh_hierarchy_opencl(p.boxes.data(), p.boxes.size(), config, nullptr, true);
  const LbvhHierarchy cpu = build_lbvh_hierarchy_reference(p.boxes.data(), p.boxes.size(), config);
  EXPECT_EQ(gpu.keys, cpu.keys);
  EXPECT_EQ(gpu.values, cpu.values);
  EXPECT_EQ(gpu.root, cpu.root);
  ASSERT_EQ(gpu.nodes.size(), cpu.nodes.size());
  // memcmp of empty vectors would pass null pointers (undefined, UBSan says): one triangle has no node.
  if (!gpu.nodes.empty()) {
    EXPECT_EQ(0, std::memcmp(gpu.nodes.data(), cpu.nodes.data(), gpu.nodes.size() * sizeof(LbvhNode)));
  }
  // And the flat Bvh written on the device equals the host conversion of the reference.
  const Bvh flat = build_lbvh(p.boxes.data(), p.boxes.size(), config);
  const Bvh ref = to_bvh(cpu, p.boxes.data());
  ASSERT_EQ(flat.nodes.size(), ref.nodes.size());
  EXPECT_EQ(0, std::memcmp(flat.nodes.data(), ref.nodes.data(), flat.nodes.size() * sizeof(Node)));
  EXPECT_EQ(flat.prim_ids, ref.prim_ids);
  // The kernels also write each node's slot range (validate() checks them against the tree)...
  EXPECT_EQ(flat.ranges.size(), flat.nodes.size() > 1 ? flat.nodes.size() : 0u);
  EXPECT_EQ(flat.validate(p.boxes.data(), p.boxes.size()), "");
  // ...and collapsing with them gives the wide tree the collapse's own walk gives.
  Bvh walked = flat;
  walked.ranges.clear();
  const WideBvh a = collapse(flat, kBlockWidth), b = collapse(walked, kBlockWidth);
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  if (!a.nodes.empty()) {
    EXPECT_EQ(0, std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(WideNode)));
  }
  EXPECT_EQ(a.root_leaf_first, b.root_leaf_first);
  EXPECT_EQ(a.root_leaf_count, b.root_leaf_count);
  // The commit's path collapses the kernels' radix tree in place, never writing the flat nodes:
  // the same wide tree, byte for byte, as collapsing the reference's flat Bvh, for leaves of one
  // block and of one primitive.
  for (const uint32_t leaf_size : {uint32_t(kBlockWidth), 1u}) {
    const WideBuild direct = build_lbvh_wide(p.boxes.data(), p.boxes.size(), leaf_size, config);
    const WideBvh expected = collapse(ref, leaf_size);
    EXPECT_EQ(direct.prim_ids, ref.prim_ids);
    ASSERT_EQ(direct.wide.nodes.size(), expected.nodes.size());
    if (!expected.nodes.empty()) {
      EXPECT_EQ(0,
                std::memcmp(direct.wide.nodes.data(), expected.nodes.data(), expected.nodes.size() * sizeof(WideNode)));
    }
    EXPECT_EQ(direct.wide.root_leaf_first, expected.root_leaf_first);
    EXPECT_EQ(direct.wide.root_leaf_count, expected.root_leaf_count);
  }
}

}  // namespace

TEST(Lbvh, KernelsEqualTheCpuReferenceNodeForNode) {
  for (MortonBits bits : {MortonBits::k30, MortonBits::k63}) {
    expect_same_as_reference(uv_sphere(120, 240, 1.0f, 0.2f), bits);
    expect_same_as_reference(triangle_soup(30000, 0.02f, 4), bits);
    expect_same_as_reference(slivers(5000, 6), bits);
  }
}

TEST(Lbvh, DuplicateMortonCodesStillGiveAValidTree) {
  // Every centroid the same: all keys equal, only the index tie-break orders the hierarchy.
  for (MortonBits bits : {MortonBits::k30, MortonBits::k63}) {
    expect_same_as_reference(copies_of_one_triangle(10000), bits);
    // Many duplicates mixed with distinct codes: a fine mesh at 30 bits has cells of several.
    expect_same_as_reference(transformed(uv_sphere(300, 600), 1.0f, Vec3(0.0f)), bits);
  }
}

TEST(Lbvh, OneAndTwoTrianglesBuild) {
  const MeshData two = triangle_soup(2, 0.1f, 8);
  expect_same_as_reference(first_triangles(two, 1), MortonBits::k30);
  expect_same_as_reference(two, MortonBits::k30);
  const Prims p = prims_of(first_triangles(two, 1));
  const Bvh one = build_lbvh(p.boxes.data(), 1);
  ASSERT_EQ(one.nodes.size(), 1u);
  EXPECT_TRUE(one.nodes[0].is_leaf());
}

TEST(Lbvh, TreeIsDeepButValidOnAMillionTriangles) {
  const MeshData m = uv_sphere(708, 708, 1.0f, 0.15f);
  const Prims p = prims_of(m);
  LbvhStats stats;
  const Bvh bvh = build_lbvh(p.boxes.data(), p.boxes.size(), {}, &stats);
  EXPECT_EQ(bvh.validate(p.boxes.data(), p.boxes.size()), "");
  EXPECT_EQ(bvh.leaf_count(), p.boxes.size());  // one primitive per leaf, as Karras builds it
  EXPECT_FALSE(stats.device.empty());
  EXPECT_FALSE(stats.stages.empty());
}

TEST(Lbvh, BrokenKernelSourceReportsTheCompilerLog) {
  try {
    opencl::compile("__kernel void broken(__global float* x) { x[0] = undefined_name; }", "");
    FAIL() << "a kernel that does not compile must raise";
  } catch (const opencl::OpenClError& e) {
    EXPECT_NE(std::string(e.what()).find("kernel build failed"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("undefined_name"), std::string::npos) << e.what();
  }
}

TEST(Lbvh, CompileTimeIsReportedApartFromBuildTime) {
  const MeshData m = triangle_soup(20000, 0.02f, 5);
  Scene scene;
  scene.add_instance(scene.add_mesh(m.vertices, m.triangles), Mat4(1.0f));
  CommitOptions options;
  options.builder = BuilderKind::Lbvh;
  options.lbvh.bits = MortonBits::k63;  // 63-bit codes take the kernels on any device
  scene.commit(options);
  const CommitStats first = scene.commit_stats();
  scene.add_instance(scene.add_mesh(m.vertices, m.triangles), Mat4(1.0f));
  scene.commit(options);
  const CommitStats second = scene.commit_stats();
  EXPECT_EQ(first.lbvh_meshes, 1u);
  EXPECT_EQ(second.lbvh_meshes, 1u);
  EXPECT_TRUE(first.warning.empty()) << first.warning;
  // Compilation happens once per process, in the first LBVH build, and is counted apart.
  EXPECT_GT(first.lbvh_compile_ms, 0.0);
  EXPECT_EQ(second.lbvh_compile_ms, 0.0);
}

TEST(LbvhFallback, WithoutOpenClTheHostBuildsTheLbvhAndTracesTheSahTreesHits) {
  // ctest runs each test in its own process, so switching OpenCL off here affects only this one.
  setenv("TOYRT_OPENCL", "off", 1);
  const MeshData m = uv_sphere(120, 240, 1.0f, 0.15f);
  auto committed = [&](BuilderKind kind) {
    auto scene = std::make_unique<Scene>();
    scene->add_instance(scene->add_mesh(m.vertices, m.triangles), Mat4(1.0f));
    CommitOptions options;
    options.builder = kind;
    scene->commit(options);
    return scene;
  };
  const auto lbvh = committed(BuilderKind::Lbvh), sah = committed(BuilderKind::Sah);
  EXPECT_EQ(lbvh->commit_stats().lbvh_meshes, 1u);
  EXPECT_EQ(lbvh->commit_stats().sah_meshes, 0u);
  EXPECT_TRUE(lbvh->commit_stats().warning.empty()) << lbvh->commit_stats().warning;
  // Rays from outside aimed at triangle centres: the nearest hit is the same triangle at the same
  // distance whichever tree finds it.
  int found = 0;
  for (size_t k = 0; k < m.triangles.size(); k += 97) {
    const Triangle& t = m.triangles[k];
    const Vec3 c = (m.vertices[t.x] + m.vertices[t.y] + m.vertices[t.z]) / 3.0f;
    const Ray ray{3.0f * c, 0.0f, glm::normalize(-c), kInfinity};
    const Hit a = lbvh->intersect(ray), b = sah->intersect(ray);
    ASSERT_EQ(a.found(), b.found()) << "triangle " << k;
    if (!a.found()) continue;
    ++found;
    EXPECT_EQ(a.prim, b.prim) << "triangle " << k;
    EXPECT_EQ(a.t, b.t) << "triangle " << k;
    EXPECT_EQ(lbvh->occluded(ray), true);
  }
  EXPECT_GT(found, 500);
}

TEST(LbvhFallback, TheHostBuildRefusesSixtyThreeBitCodes) {
  const PrimitiveBounds p = triangle_bounds(uv_sphere(10, 10));
  BuildConfig config;
  config.lbvh.bits = MortonBits::k63;
  config.lbvh.device = LbvhDevice::Host;
  EXPECT_THROW(build_wide_bvh(BuilderKind::Lbvh, p.boxes.data(), p.boxes.size(), 8, config), std::invalid_argument);
}

TEST(LbvhFallback, WithoutOpenClSixtyThreeBitCodesFallBackOnSahWithOneWarning) {
  // The host build makes 30-bit codes only: 63-bit ones need the kernels.
  setenv("TOYRT_OPENCL", "off", 1);
  const MeshData m = uv_sphere(30, 60);
  Scene scene;
  const uint32_t id = scene.add_mesh(m.vertices, m.triangles);
  scene.add_instance(id, Mat4(1.0f));
  scene.add_mesh(m.vertices, m.triangles);  // two meshes: still one warning
  CommitOptions options;
  options.builder = BuilderKind::Lbvh;
  options.lbvh.bits = MortonBits::k63;
  scene.commit(options);
  EXPECT_EQ(scene.commit_stats().sah_meshes, 2u);
  EXPECT_EQ(scene.commit_stats().lbvh_meshes, 0u);
  EXPECT_NE(scene.commit_stats().warning.find("SAH builder instead"), std::string::npos);
  EXPECT_NE(scene.commit_stats().warning.find("TOYRT_OPENCL=off"), std::string::npos);
  // And the scene works.
  EXPECT_TRUE(scene.intersect(Ray{Vec3(0, 0, 5), 0.0f, Vec3(0, 0, -1), kInfinity}).found());
}

TEST(BuilderChoice, AutoPicksLbvhForFewRaysAndSahForMany) {
  const BuilderCostModel model;
  EXPECT_EQ(model.choose(1000000, -1.0), BuilderKind::Sah);  // unknown: keep the faster trees
  EXPECT_EQ(model.choose(1000000, 1e5), BuilderKind::Lbvh);  // a quick preview of a big mesh
  EXPECT_EQ(model.choose(1000000, 1e9), BuilderKind::Sah);   // a long render
  // The break-even point follows the model's own formula.
  const double n = 1e6;
  const double even = n * (model.sah_build_ns - model.lbvh_build_ns) / (model.trace_ns * (model.lbvh_trace_factor - 1));
  EXPECT_EQ(model.choose(size_t(n), even * 0.99), BuilderKind::Lbvh);
  EXPECT_EQ(model.choose(size_t(n), even * 1.01), BuilderKind::Sah);
}
