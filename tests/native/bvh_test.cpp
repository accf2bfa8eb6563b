// The binned SAH builder's output: structural invariants, determinism, hard inputs, and exact
// agreement of traversal with testing every triangle.
#include "accel/binned_sah_builder.h"
#include "accel/builder.h"
#include "core/parallel.h"
#include "geometry/mesh.h"
#include "geometry/triangle.h"
#include "test_scenes.h"

#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <memory>
#include <random>

using namespace toyrt;
using namespace toyrt::testing;

namespace {

std::vector<BBox> triangle_boxes(const MeshData& m) { return triangle_bounds(m).boxes; }

// The binary tree a mesh's SAH commit builds (with its leaf setting) before the collapse.
Bvh sah_tree(const MeshData& m, int threads = 0) {
  const auto boxes = triangle_boxes(m);
  BuildConfig config;
  config.sah.leaf_without_search = kBlockWidth;
  Bvh bvh;
  run_with_threads(threads, [&] { bvh = build_bvh(BuilderKind::Sah, boxes.data(), boxes.size(), config); });
  return bvh;
}

Mesh built(const MeshData& m, int threads = 0) {
  Mesh mesh(m.vertices, m.triangles);
  run_with_threads(threads, [&] { mesh.build(); });
  return mesh;
}

// Nearest hit by testing every triangle: the reference a BVH must reproduce exactly.
Hit brute_force(const MeshData& m, const Ray& ray) {
  const WatertightRay wr = make_watertight_ray(ray.org, ray.dir);
  Hit best;
  best.t = ray.tfar;
  for (size_t i = 0; i < m.triangles.size(); ++i) {
    const Triangle& t = m.triangles[i];
    float th, u, v;
    if (intersect_triangle(wr, m.vertices[t.x], m.vertices[t.y], m.vertices[t.z], ray.tnear, best.t, th, u, v)) {
      best = {th, u, v, int32_t(i), 0};
    }
  }
  if (!best.found()) return Hit{};
  const Triangle& t = m.triangles[size_t(best.prim)];
  refine_hit(ray.org, ray.dir, m.vertices[t.x], m.vertices[t.y], m.vertices[t.z], ray.tnear, best.t, best.u, best.v);
  return best;
}

}  // namespace

TEST(BinnedSahBuilder, InvariantsHoldOnVariedMeshes) {
  for (const MeshData& m : {uv_sphere(40, 80), bicone_fan(3000), triangle_soup(20000, 0.02f, 1), slivers(5000, 2),
                            transformed(uv_sphere(30, 60, 1.0f, 0.2f), 1e-3f, Vec3(1e5f, -1e5f, 3e4f))}) {
    const Bvh bvh = sah_tree(m);
    const auto boxes = triangle_boxes(m);
    EXPECT_EQ(bvh.validate(boxes.data(), boxes.size()), "");
    EXPECT_LE(bvh.depth(), kMaxBvhDepth);
  }
}

TEST(BinnedSahBuilder, SameTreeForAnyThreadCount) {
  const MeshData m = uv_sphere(300, 600, 1.0f, 0.1f);  // large enough for the parallel paths
  const Bvh one = sah_tree(m, 1), two = sah_tree(m, 2), all = sah_tree(m, 0);
  for (const Bvh* other : {&two, &all}) {
    ASSERT_EQ(one.nodes.size(), other->nodes.size());
    EXPECT_EQ(0, std::memcmp(one.nodes.data(), other->nodes.data(), one.nodes.size() * sizeof(Node)));
    EXPECT_EQ(one.prim_ids, other->prim_ids);
  }
}

// What tracing reads (wide nodes and triangle blocks) is byte for byte the same on 1, 2 and all
// threads, from either builder: traversal results cannot depend on the thread count.
TEST(Mesh, TracedLayoutSameForAnyThreadCount) {
  const MeshData m = uv_sphere(300, 600, 1.0f, 0.1f);  // above the collapse's parallel threshold
  // The SAH, the host LBVH (a CPU device's) and the kernels' LBVH collapsed in place.
  for (const auto& [kind, device] :
       {std::pair{BuilderKind::Sah, LbvhDevice::Auto}, std::pair{BuilderKind::Lbvh, LbvhDevice::Host},
        std::pair{BuilderKind::Lbvh, LbvhDevice::OpenCl}}) {
    SCOPED_TRACE(std::string(builder_name(kind)) + (device == LbvhDevice::OpenCl ? " (kernels)" : ""));
    BuildConfig config;
    config.lbvh.device = device;
    auto build = [&](int threads) {
      auto mesh = std::make_unique<Mesh>(m.vertices, m.triangles);
      run_with_threads(threads, [&] { mesh->build(kind, config); });
      return mesh;
    };
    const auto one = build(1), two = build(2), all = build(0);
    for (const Mesh* other : {two.get(), all.get()}) {
      const auto& a = one->wide_bvh().nodes;
      const auto& b = other->wide_bvh().nodes;
      ASSERT_EQ(a.size(), b.size());
      EXPECT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * sizeof(WideNode)));
      ASSERT_EQ(one->blocks().size(), other->blocks().size());
      EXPECT_EQ(
          0, std::memcmp(one->blocks().data(), other->blocks().data(), one->blocks().size() * sizeof(TriangleBlock)));
    }
  }
}

TEST(Mesh, EverySlotBoxIsItsTrianglesExactBoundsAndSlotsAreInAnyHitOrder) {
  // The host LBVH leaves its boxes to Mesh::finish, which bounds each leaf as it copies its
  // triangles and each interior slot from its child (complete_wide_boxes); the SAH collapse makes
  // its own. Either way: a slot's box is exactly the bounds of the triangles under it (min and
  // max are exact, so equality), and a node's used slots come first, by non-increasing area.
  // 559,800 triangles: beyond a core's L2 (the boxes deferred) and beyond kPrefetchBlockBytes
  // (the blocks streamed, fenced at the end of each of the bottom-up pass's tasks).
  const MeshData m = uv_sphere(400, 700, 1.0f, 0.1f);
  for (const BuilderKind kind : {BuilderKind::Lbvh, BuilderKind::Sah}) {
    SCOPED_TRACE(builder_name(kind));
    BuildConfig config;
    config.lbvh.device = LbvhDevice::Host;
    Mesh mesh(m.vertices, m.triangles);
    mesh.build(kind, config);
    EXPECT_GT(mesh.blocks().size() * sizeof(TriangleBlock), size_t(16) << 20);  // streamed
    const auto& nodes = mesh.wide_bvh().nodes;
    ASSERT_FALSE(nodes.empty());
    size_t wrong_boxes = 0, wrong_order = 0;
    std::function<BBox(uint32_t)> bounds_of = [&](uint32_t i) {
      BBox all;
      const WideNode& n = nodes[i];
      for (int k = 0; k < kWidth; ++k) {
        if (!n.used(k)) {
          for (int j = k; j < kWidth; ++j) wrong_order += n.used(j);
          break;
        }
        if (k > 0 && n.box(k).half_area() > n.box(k - 1).half_area()) ++wrong_order;
        BBox b;
        if (n.count[k] == 0) {
          b = bounds_of(n.child[k]);
        } else {
          const uint32_t blocks = (n.count[k] + kBlockWidth - 1) / kBlockWidth;
          for (uint32_t q = n.child[k]; q < n.child[k] + blocks; ++q)
            for (int lane = 0; lane < kBlockWidth; ++lane)
              if (mesh.blocks()[q].prim[lane] != kNoTriangle)
                for (int v = 0; v < 3; ++v) b.extend(mesh.blocks()[q].vertex(lane, v));
        }
        const BBox slot = n.box(k);
        wrong_boxes += !(slot.lo == b.lo && slot.hi == b.hi);
        all.extend(b);
      }
      return all;
    };
    const BBox root = bounds_of(0);
    EXPECT_EQ(wrong_boxes, 0u);
    EXPECT_EQ(wrong_order, 0u);
    EXPECT_EQ(root.lo, mesh.bounds().lo);
    EXPECT_EQ(root.hi, mesh.bounds().hi);
  }
}

TEST(Mesh, RaysFindTheNearestTriangleAndOccludersWhereTheBlocksAreBeyondTheCaches) {
  // Blocks beyond kPrefetchBlockBytes take the closest-hit walk that visits a stacked node while
  // the nearest leaf's block arrives (closest_hit_wide<true>): every ray must still find a nearest
  // triangle, the one a loop over all triangles finds (or one at the same distance, where the ray
  // meets an edge or vertex); and, naming that triangle as the one it leaves (Ray::self), the
  // nearest of the others. Occlusion takes the any-hit walk with a leaf in flight
  // (any_hit_wide<true>): a segment just past that nearest distance is blocked, one just short of
  // it is not.
  const MeshData m = uv_sphere(400, 700, 1.0f, 0.1f);
  Mesh mesh(m.vertices, m.triangles);
  mesh.build(BuilderKind::Sah, BuildConfig{});
  ASSERT_GT(mesh.blocks().size() * sizeof(TriangleBlock), Mesh::kPrefetchBlockBytes);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  int hits = 0;
  for (int k = 0; k < 40; ++k) {
    const Vec3 org = 3.0f * glm::normalize(Vec3(unit(rng), unit(rng), unit(rng)));
    const Vec3 dir = 0.8f * Vec3(unit(rng), unit(rng), unit(rng)) - org;
    const WatertightRay ray = make_watertight_ray(org, dir);
    auto distance_to = [&](size_t i, float tfar, float& t) {
      const Triangle& tri = m.triangles[i];
      float u, v;
      return intersect_triangle(ray, m.vertices[tri[0]], m.vertices[tri[1]], m.vertices[tri[2]], 0.0f, tfar, t, u, v);
    };
    // The nearest distance over every triangle but `skip`.
    auto nearest_but = [&](int64_t skip) {
      float nearest = kInfinity, t;
      for (size_t i = 0; i < m.triangles.size(); ++i)
        if (int64_t(i) != skip && distance_to(i, nearest, t)) nearest = t;
      return nearest;
    };
    int32_t first_prim = kInvalidId;
    for (int pass = 0; pass < 2; ++pass) {
      // Pass 0: no triangle named; pass 1: the first pass's triangle named (the kSkip walk).
      const int32_t skip = pass == 0 ? int32_t(kInvalidId) : first_prim;
      const float nearest = nearest_but(pass == 0 ? -1 : skip);
      float tfar = kInfinity, u, v, t;
      int32_t prim = -1;
      const bool found = mesh.intersect(org, dir, 0.0f, tfar, u, v, prim, false, skip);
      ASSERT_EQ(found, nearest < kInfinity) << "ray " << k << " pass " << pass;
      ASSERT_EQ(mesh.occluded(org, dir, 0.0f, found ? nearest * 1.0001f : kInfinity, false, skip), found)
          << "ray " << k << " pass " << pass;
      if (found) {
        ASSERT_FALSE(mesh.occluded(org, dir, 0.0f, nearest * 0.9999f, false, skip)) << "ray " << k;
      }
      if (!found) break;
      hits += pass == 0;
      ASSERT_NE(prim, skip);
      ASSERT_TRUE(distance_to(size_t(prim), kInfinity, t));
      EXPECT_EQ(t, nearest) << "ray " << k << " pass " << pass;
      first_prim = prim;
    }
  }
  EXPECT_GT(hits, 20);
}

TEST(Mesh, OccludersMatchTheNearestHitWhereALeafIsKeptInFlight) {
  // Blocks beyond kLeafInFlightBlockBytes take the any-hit walk that tests each leaf a step after
  // requesting it (any_hit_wide<true>): a segment just past a ray's nearest hit (the closest-hit
  // walk's, which the test above checks against every triangle) is blocked, one just short of it
  // is not, with and without the triangle the ray leaves named.
  const MeshData m = uv_sphere(1200, 1200, 1.0f, 0.1f);
  Mesh mesh(m.vertices, m.triangles);
  mesh.build(BuilderKind::Sah, BuildConfig{});
  ASSERT_GT(mesh.blocks().size() * sizeof(TriangleBlock), Mesh::kLeafInFlightBlockBytes);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  int hits = 0, misses = 0;
  for (int k = 0; k < 400; ++k) {
    const Vec3 org = 3.0f * glm::normalize(Vec3(unit(rng), unit(rng), unit(rng)));
    const Vec3 dir = 1.5f * Vec3(unit(rng), unit(rng), unit(rng)) - org;
    float tfar = kInfinity, u, v;
    int32_t prim = -1;
    if (!mesh.intersect(org, dir, 0.0f, tfar, u, v, prim)) {
      ++misses;
      ASSERT_FALSE(mesh.occluded(org, dir, 0.0f, kInfinity)) << "ray " << k;
      continue;
    }
    ++hits;
    ASSERT_TRUE(mesh.occluded(org, dir, 0.0f, tfar * 1.0001f)) << "ray " << k;
    ASSERT_FALSE(mesh.occluded(org, dir, 0.0f, tfar * 0.9999f)) << "ray " << k;
    // Leaving the hit triangle towards the far side of the sphere: the next hit blocks it.
    float next = kInfinity;
    const int32_t first = prim;
    const bool again = mesh.intersect(org, dir, 0.0f, next, u, v, prim, false, first);
    ASSERT_EQ(mesh.occluded(org, dir, 0.0f, again ? next * 1.0001f : kInfinity, false, first), again) << "ray " << k;
    if (again) {
      ASSERT_FALSE(mesh.occluded(org, dir, 0.0f, next * 0.9999f, false, first)) << "ray " << k;
    }
  }
  EXPECT_GT(hits, 100);
  EXPECT_GT(misses, 20);
}

TEST(BinnedSahBuilder, CoincidentCentroidsStayShallow) {
  // 100,000 copies of one triangle: no plane separates them; splits must still halve the range.
  MeshData m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.triangles.assign(100000, Triangle(0, 1, 2));
  const Bvh bvh = sah_tree(m);
  const auto boxes = triangle_boxes(m);
  EXPECT_EQ(bvh.validate(boxes.data(), boxes.size()), "");
  EXPECT_LE(bvh.depth(), 20);
}

TEST(BinnedSahBuilder, AdversarialSpacingStaysWithinStackDepth) {
  // Triangles at exponentially growing distances: SAH alone would peel one off per level.
  MeshData m;
  for (int i = 0; i < 4000; ++i) {
    const float x = std::ldexp(1.0f, i % 120 - 60) * (1.0f + 1e-3f * float(i));
    const uint32_t b = uint32_t(m.vertices.size());
    m.vertices.push_back({x, 0, 0});
    m.vertices.push_back({x, 1e-30f + x * 1e-3f, 0});
    m.vertices.push_back({x, 0, 1e-30f + x * 1e-3f});
    m.triangles.push_back({b, b + 1, b + 2});
  }
  const Bvh bvh = sah_tree(m);
  const auto boxes = triangle_boxes(m);
  EXPECT_EQ(bvh.validate(boxes.data(), boxes.size()), "");
}

TEST(BinnedSahBuilder, OneAndTwoPrimitives) {
  MeshData one;
  one.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  one.triangles = {{0, 1, 2}};
  EXPECT_EQ(sah_tree(one).nodes.size(), 1u);
  MeshData two = one;
  two.triangles.push_back({0, 1, 3});
  const Bvh bvh = sah_tree(two);
  const auto boxes = triangle_boxes(two);
  EXPECT_EQ(bvh.validate(boxes.data(), boxes.size()), "");
}

TEST(BinnedSahBuilder, SahCostBeatsALeafOfEverything) {
  const MeshData m = uv_sphere(100, 200);
  const Bvh bvh = sah_tree(m);
  // A single leaf costs one test per triangle; a good tree needs a few dozen.
  EXPECT_LT(bvh.sah_cost(), 100.0);
  EXPECT_GT(bvh.sah_cost(), 1.0);
}

TEST(Bvh, TraversalAgreesExactlyWithTestingEveryTriangle) {
  for (const MeshData& m : {uv_sphere(12, 24, 1.0f, 0.3f), triangle_soup(3000, 0.05f, 3), slivers(500, 4)}) {
    const Mesh mesh = built(m);
    auto rays = primary_rays(bounds_of(m), 64, 48);
    std::vector<Hit> hits;
    for (const Ray& r : rays) {
      Hit h;
      float tfar = r.tfar;
      if (mesh.intersect(r.org, r.dir, r.tnear, tfar, h.u, h.v, h.prim)) h.t = tfar;
      hits.push_back(h);
      const Hit ref = brute_force(m, r);
      ASSERT_EQ(h.found(), ref.found());
      if (ref.found()) {
        EXPECT_EQ(h.t, ref.t);  // the same arithmetic on the same triangle: bit-identical
      }
      EXPECT_EQ(mesh.occluded(r.org, r.dir, r.tnear, r.tfar), ref.found());
    }
    for (const Ray& r : diffuse_rays(m, rays, hits, 5)) {
      float tfar = r.tfar, u, v;
      int32_t prim = -1;
      const bool found = mesh.intersect(r.org, r.dir, r.tnear, tfar, u, v, prim);
      const Hit ref = brute_force(m, r);
      ASSERT_EQ(found, ref.found());
      if (found) {
        EXPECT_EQ(tfar, ref.t);
      }
    }
  }
}

// The same exact agreement for rays that start elsewhere than at their origin: before it (tnear
// -1), at -0 and 0, halfway to the first surface, and just past it, where the triangles the ray
// crosses first lie wholly ahead of its origin but before its start (start_side must leave
// them to the error bound when tnear > 0).
TEST(Bvh, TraversalAgreesExactlyWithTestingEveryTriangleFromAnyStart) {
  for (const MeshData& m : {uv_sphere(12, 24, 1.0f, 0.3f), triangle_soup(3000, 0.05f, 3), slivers(500, 4)}) {
    const Mesh mesh = built(m);
    const auto camera = primary_rays(bounds_of(m), 48, 36);
    std::vector<Hit> hits;
    for (const Ray& r : camera) hits.push_back(brute_force(m, r));
    std::vector<Ray> rays = camera;
    for (const Ray& r : diffuse_rays(m, camera, hits, 7)) rays.push_back(r);
    int compared = 0, found = 0;
    for (const Ray& base : rays) {
      const Hit first = brute_force(m, base);
      const float halfway = first.found() ? 0.5f * first.t : 1.0f, past = first.found() ? 1.01f * first.t : 2.0f;
      for (const float tnear : {-1.0f, -0.0f, 0.0f, halfway, past}) {
        Ray r = base;
        r.tnear = tnear;
        const Hit ref = brute_force(m, r);
        float tfar = r.tfar, u, v;
        int32_t prim = -1;
        const bool hit = mesh.intersect(r.org, r.dir, r.tnear, tfar, u, v, prim);
        ASSERT_EQ(hit, ref.found()) << "tnear " << tnear;
        if (hit) {
          EXPECT_EQ(tfar, ref.t);
          EXPECT_EQ(prim, ref.prim);
          ++found;
        }
        EXPECT_EQ(mesh.occluded(r.org, r.dir, r.tnear, r.tfar), ref.found());
        ++compared;
      }
    }
    EXPECT_GT(found, 0);
    EXPECT_GT(compared, 1000);
  }
}

// A determinant that overflows (sheared coordinates near 1e19, edge functions near 1.5e38 each,
// their sum beyond float) makes the float distance T / det meaningless; the distance is then
// decided in double precision: the crossing at 1e-10 is found, and a segment ending before it
// is not blocked. (start_side once accepted such a lane at t = -0, and as a blocker of any segment.)
TEST(Mesh, AnOverflowingDeterminantLeavesTheDistanceToDoublePrecision) {
  const float a = 1.22e19f, z = 1e-10f;
  const MeshData m{{{a, 0.0f, z}, {0.0f, a, z}, {-a, -a, z}}, {{0, 1, 2}}};
  const Mesh mesh = built(m);
  const Vec3 o(0.0f), d(0.0f, 0.0f, 1.0f);
  float tfar = kInfinity, u, v;
  int32_t prim = -1;
  ASSERT_TRUE(mesh.intersect(o, d, 0.0f, tfar, u, v, prim));
  EXPECT_NEAR(tfar, z, 1e-6f * z);
  EXPECT_EQ(prim, 0);
  EXPECT_FALSE(mesh.occluded(o, d, 0.0f, 0.1f * z));
  EXPECT_TRUE(mesh.occluded(o, d, 0.0f, 10.0f * z));
  float t, tu, tv;
  EXPECT_FALSE(intersect_triangle(make_watertight_ray(o, d), m.vertices[0], m.vertices[1], m.vertices[2], 0.0f,
                                  0.1f * z, t, tu, tv));
}

// The any-hit walk visits a node's children in slot order, so collapse() stores them by
// decreasing box area (the likeliest blockers first), with the empty slots last.
TEST(WideBvh, ChildrenAreStoredByDecreasingArea) {
  const Mesh mesh = built(in_closed_room(uv_sphere(60, 60, 1.0f, 0.15f), 0.5f));
  const WideBvh& wide = mesh.wide_bvh();
  ASSERT_FALSE(wide.nodes.empty());
  for (const WideNode& n : wide.nodes) {
    float previous = kInfinity;
    for (int i = 0; i < kWidth; ++i) {
      BBox b;
      b.lo = {n.bounds[0][i], n.bounds[1][i], n.bounds[2][i]};
      b.hi = {n.bounds[3][i], n.bounds[4][i], n.bounds[5][i]};
      const float area = b.lo.x <= b.hi.x ? b.half_area() : -1.0f;  // an empty slot: below any box
      EXPECT_LE(area, previous);
      previous = area;
    }
  }
}

// A shadow ray from the model to a light outside the room is blocked (by a wall or the model),
// and the any-hit walk agrees with the closest hit on every ray, whichever child it visits first.
TEST(WideBvh, AnyHitAgreesWithClosestHitInAClosedRoom) {
  const MeshData sphere = uv_sphere(40, 40, 1.0f, 0.15f);
  const MeshData room = in_closed_room(sphere, 0.5f);
  const Mesh mesh = built(room);
  const std::vector<Ray> camera = primary_rays(bounds_of(sphere), 48, 36);
  std::vector<Ray> aimed;
  std::vector<Hit> hits;
  const Mesh bare = built(sphere);
  for (const Ray& r : camera) {
    Hit h;
    float tfar = r.tfar;
    if (bare.intersect(r.org, r.dir, r.tnear, tfar, h.u, h.v, h.prim)) h.t = tfar;
    aimed.push_back(r);
    hits.push_back(h);
  }
  const std::vector<Ray> shadows = shadow_rays(sphere, aimed, hits, Vec3(-4.0f, -9.0f, 13.0f));
  ASSERT_GT(shadows.size(), 100u);
  for (const Ray& r : shadows) {
    float tfar = r.tfar, u, v;
    int32_t prim = -1;
    EXPECT_TRUE(mesh.intersect(r.org, r.dir, r.tnear, tfar, u, v, prim));
    EXPECT_TRUE(mesh.occluded(r.org, r.dir, r.tnear, r.tfar));
  }
}
