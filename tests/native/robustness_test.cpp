// Regression tests for what the fuzzer (tests/fuzz) found, with its inputs written out (hex
// floats are exact). The builder cases were undefined behaviour that happened to work on x86:
// they fail under `make sanitize` (UBSan aborts) and otherwise check the trees stay valid.
#include "accel/binned_sah_builder.h"
#include "accel/lbvh_builder.h"
#include "geometry/triangle.h"
#include "scene/scene.h"

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include <cfloat>
#include <cmath>
#include <random>
#include <string>
#include <vector>

using namespace toyrt;

namespace {

struct Boxes {
  std::vector<BBox> boxes;
  void add(const Vec3& a, const Vec3& b) {
    BBox box;
    box.extend(a);
    box.extend(b);
    boxes.push_back(box);
  }
};

// A scene of one triangle placed `instances` times at the identity (2 or more: the top level runs).
Scene one_triangle(const Vec3& p0, const Vec3& p1, const Vec3& p2, int instances) {
  Scene s;
  s.add_mesh({p0, p1, p2}, {Triangle(0, 1, 2)});
  for (int i = 0; i < instances; ++i) s.add_instance(0, Mat4(1.0f));
  s.commit();
  return s;
}

}  // namespace

TEST(BBox, CentreOfABoxAtFloatMaxIsFinite) {
  BBox b;
  b.extend(Vec3(FLT_MAX));
  EXPECT_EQ(b.center(), Vec3(FLT_MAX));  // (lo + hi) / 2 overflowed to inf
}

TEST(BinnedSah, CentroidsSpanningMoreThanFloatMaxGiveAValidTree) {
  Boxes p;
  for (int i = 0; i < 20; ++i)
    p.add(Vec3(i % 2 ? FLT_MAX : -FLT_MAX, float(i), 0.0f), Vec3(i % 2 ? FLT_MAX : -FLT_MAX, float(i) + 1, 1.0f));
  p.add(Vec3(0.0f), Vec3(1.0f));
  const Bvh bvh = build_binned_sah(p.boxes.data(), p.boxes.size());
  EXPECT_EQ(bvh.validate(p.boxes.data(), p.boxes.size()), "");
}

TEST(BinnedSah, DenormalCentroidExtentGivesAValidTree) {
  Boxes p;
  for (int i = 0; i < 20; ++i) p.add(Vec3(float(i % 3) * 1e-45f, 0.0f, 0.0f), Vec3(float(i % 3) * 1e-45f, 1.0f, 1.0f));
  const Bvh bvh = build_binned_sah(p.boxes.data(), p.boxes.size());
  EXPECT_EQ(bvh.validate(p.boxes.data(), p.boxes.size()), "");
}

TEST(LbvhReference, DenormalCentroidExtentGivesAValidTree) {
  // cells / 1e-45 is an infinite scale, and 0 * inf a NaN Morton coordinate before the fix.
  Boxes p;
  for (int i = 0; i < 20; ++i)
    p.add(Vec3(float(i % 3) * 1e-45f, float(i), 0.0f), Vec3(float(i % 3) * 1e-45f, float(i), 1.0f));
  for (MortonBits bits : {MortonBits::k30, MortonBits::k63}) {
    const Bvh bvh = build_lbvh_reference(p.boxes.data(), p.boxes.size(), LbvhConfig{bits});
    EXPECT_EQ(bvh.validate(p.boxes.data(), p.boxes.size()), "");
  }
}

TEST(Scene, ABoxBehindTheOriginIsNotMissedByRounding) {
  // The ray passes through the triangle's vertex at the origin, at t = -1, which is also a corner
  // of the instance's box. Ize's widening (exit * (1 + 2 gamma)) narrows a negative exit: the top
  // level missed the box, so intersect() found nothing while a brute-force test hits.
  const float o = 0x1.555558p+0f;
  Ray r;
  r.org = Vec3(o);
  r.dir = Vec3(o);
  r.tnear = -4.0f;
  r.tfar = 1.5f;
  const Scene s = one_triangle(Vec3(0.0f), Vec3(-3.5f, -4.0f, 3.5f), Vec3(-1.0f, -0x1.1b6d48p+0f, 1.5f), 2);
  const Hit h = s.intersect(r);
  ASSERT_TRUE(h.found());
  EXPECT_FLOAT_EQ(h.t, -1.0f);
  EXPECT_TRUE(s.occluded(r));
}

TEST(Scene, OccludedSeesSegmentsThatEndBeforeTheOrigin) {
  // Any-hit walks stacked subtrees with an entry distance of 0, then skipped them as "beyond
  // tfar" when tfar < 0. A row of triangles behind the ray's origin, each hit by its own ray.
  std::vector<Vec3> v;
  std::vector<Triangle> t;
  for (uint32_t i = 0; i < 64; ++i) {
    const Vec3 c(float(i % 8) * 3.0f, float(i / 8) * 3.0f, -5.0f);
    v.insert(v.end(), {c, c + Vec3(1, 0, 0), c + Vec3(0, 1, 0)});
    t.emplace_back(3 * i, 3 * i + 1, 3 * i + 2);
  }
  Scene s;
  s.add_instance(s.add_mesh(v, t), Mat4(1.0f));
  s.commit();
  for (uint32_t i = 0; i < 64; ++i) {
    Ray r;
    r.org = v[3 * i] + Vec3(0.25f, 0.25f, 5.0f);
    r.dir = Vec3(0, 0, 1);  // away from the triangles: the hit is at t = -5
    r.tnear = -10.0f;
    r.tfar = -1.0f;
    EXPECT_FLOAT_EQ(s.intersect(r).t, -5.0f) << i;
    EXPECT_TRUE(s.occluded(r)) << i;
  }
}

TEST(Scene, RefinedHitDistanceStaysBeforeTfar) {
  // The float test accepted a hit just before tfar = 0; the double-precision refinement then
  // rounded its distance to 0 = tfar, outside the half-open segment [tnear, tfar).
  const float a = 0x1.16c2p-133f, b = 0x1.281a0ep-119f;
  Ray r;
  r.org = Vec3(-0x1.676766p-24f);
  r.dir = Vec3(-0x1p-25f, 0x1.7d9dap+0f, -0x1.6767a8p-24f);
  r.tnear = -0x1.a9a9a8p+42f;
  r.tfar = 0.0f;
  for (int instances = 1; instances <= 3; ++instances) {
    const Scene s = one_triangle(Vec3(a, a, b), Vec3(-4.0f), Vec3(2.0f, -2.0f, 0x1p-126f), instances);
    const Hit h = s.intersect(r);
    ASSERT_TRUE(h.found()) << instances;
    EXPECT_LT(h.t, r.tfar) << instances;
    EXPECT_GE(h.t, r.tnear) << instances;
    EXPECT_TRUE(s.occluded(r)) << instances;
  }
}

TEST(Scene, RayOverflowingInAnInstancesObjectSpaceMisses) {
  // A finite world ray through an instance scaled by 1e-12: in object space its direction is
  // inf - inf = NaN in every component. The wide walk then took empty child slots for hits and
  // re-entered the root until its stack overflowed (a segfault from Python).
  std::vector<Vec3> v;
  std::vector<Triangle> t;
  for (uint32_t i = 0; i < 20; ++i) {
    const Vec3 c(float(i % 5), float(i / 5), 0.0f);
    v.insert(v.end(), {c, c + Vec3(1, 0, 0), c + Vec3(0, 1, 0)});
    t.emplace_back(3 * i, 3 * i + 1, 3 * i + 2);
  }
  // to_object = 1e12 * B with B's first two columns of one sign, so x - y cancels to NaN in each row.
  const glm::mat3 b(1, 1, 1, 1, 1, 2, 0, 1, 1);  // columns
  Mat4 to_world(glm::inverse(b) * 1e-12f);
  Scene s;
  const uint32_t mesh = s.add_mesh(v, t);
  s.add_instance(mesh, to_world);
  s.add_instance(mesh, Mat4(1.0f));
  s.commit();
  Ray r;
  r.org = Vec3(0.0f, 0.0f, 5.0f);
  r.dir = Vec3(FLT_MAX, -FLT_MAX, 0.0f);
  EXPECT_FALSE(s.intersect(r).found());
  EXPECT_FALSE(s.occluded(r));
  // Through the same overflowing instance, an ordinary ray still finds the identity instance.
  r.dir = Vec3(0.0f, 0.0f, -1.0f);
  r.org = Vec3(0.25f, 0.25f, 5.0f);
  EXPECT_EQ(s.intersect(r).instance, 1);
}

TEST(Scene, TransformWithDependentRowsIsRefusedAsNearlySingular) {
  // Found by the fuzzer (2026-12-06): to_world's first two rows are equal in their linear part,
  // so it is singular, but the determinant of its rounded products is not exactly 0 and the
  // float inverse was accepted. Rays carried through that "inverse" had nothing to do with the
  // world ray: the top level's box dropped an instance whose object-space ray hits its triangle.
  const float c = 0x1.555558p+0f;
  Mat4 to_world(1.0f);
  to_world[0] = glm::vec4(c, c, 0x1.55555p+0f, 0.0f);  // columns (glm is column-major)
  to_world[1] = glm::vec4(c, c, c, 0.0f);
  to_world[2] = glm::vec4(c, c, -0x1.b96df8p-1f, 0.0f);
  to_world[3] = glm::vec4(-0.0f, -0x1.a8b9e8p-1f, 2.5f, 1.0f);
  Scene s;
  const uint32_t mesh = s.add_mesh({Vec3(0, -4, 0), Vec3(0, 0, 0), Vec3(-4, -4, -4)}, {Triangle(0, 1, 2)});
  s.add_instance(mesh, Mat4(1.0f));
  try {
    s.add_instance(mesh, to_world);
    FAIL() << "a transform with dependent rows was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("nearly singular"), std::string::npos) << e.what();
  }
  EXPECT_EQ(s.instance_count(), 1u);  // the refused instance left nothing behind
}

namespace {

// Whether a ray carried into the instance's object space as Scene::trace_instance does it hits
// the triangle (the brute-force side of the fuzzer's property).
bool object_space_hit(const Instance& inst, const Vec3& p0, const Vec3& p1, const Vec3& p2, const Ray& r) {
  const Vec3 org(inst.to_object * glm::vec4(r.org, 1.0f));
  const Vec3 dir = glm::mat3(inst.to_object) * r.dir;
  float t, u, v;
  return intersect_triangle(make_watertight_ray(org, dir), p0, p1, p2, r.tnear, r.tfar, t, u, v);
}

}  // namespace

TEST(Scene, InstanceBoxesHoldEveryHitOfTheRaysTheMeshesSee) {
  // Instances turned about z, so a triangle corner is the x-most point of each world box. Rays
  // come from far away (|o| 1e4 - 6e5) with no x component, down a slope onto the corner or just
  // beside it (+-0.02): the world ray's x is exact, so the slab test grants no slack in x, while
  // the ray's object-space form is rounded by about 1e-7 |o| there. The top level padded its
  // boxes by ulps of their own size: it dropped 552 of these 20,000 rays, which the object-space
  // ray hits. Property: the scene hits exactly when the object-space ray of some instance does.
  const Vec3 p0(0.0f), p1(1.0f, 0.0f, 0.0f), p2(0.0f, 1.0f, 0.0f);
  Scene s;
  const uint32_t mesh = s.add_mesh({p0, p1, p2}, {Triangle(0, 1, 2)});
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  const int kInstances = 6;
  for (int i = 0; i < kInstances; ++i) {
    Mat4 m = glm::translate(Mat4(1.0f), Vec3(100.0f * unit(rng), 100.0f * unit(rng), 100.0f * unit(rng)));
    m = glm::rotate(m, 0.75f + 0.6f * unit(rng), Vec3(0, 0, 1));  // (1, 0, 0) stays the x-most corner
    m = glm::scale(m, Vec3(std::exp2(4.0f * unit(rng))));
    s.add_instance(mesh, m);
  }
  s.commit();
  int hits = 0, wrong = 0;
  const int kRays = 20000;
  for (int k = 0; k < kRays; ++k) {
    const Instance& inst = s.instance(uint32_t(k % kInstances));
    const Vec3 target = Vec3(inst.to_world * glm::vec4(p1, 1.0f)) + Vec3(0.02f * unit(rng), 0.0f, 0.0f);
    const float side = unit(rng) < 0.0f ? -1.0f : 1.0f;
    const Vec3 dir = glm::normalize(Vec3(0.0f, side, -std::exp2(-3.0f * (unit(rng) + 1.0f))));
    Ray r;
    r.org = target - dir * (1e4f * std::exp2(3.0f * (unit(rng) + 1.0f)));
    r.dir = dir;
    bool expected = false;
    for (uint32_t i = 0; i < s.instance_count(); ++i) expected |= object_space_hit(s.instance(i), p0, p1, p2, r);
    wrong += s.intersect(r).found() != expected;
    wrong += s.occluded(r) != expected;
    hits += expected;
  }
  EXPECT_EQ(wrong, 0);
  EXPECT_GT(hits, kRays / 5);  // the corner is grazed from both sides
  EXPECT_LT(hits, kRays * 4 / 5);
}
