// collapse(): the 8-wide layout derived from a binary tree, greedy and by the SAH dynamic
// programme. Structural invariants with known answers (every primitive in exactly one leaf, no
// node narrower than two children), the programme's optimality against the greedy collapse under
// the same cost, and a layout that does not depend on the thread count. And the closest-hit walk
// over it with and without overlapped leaf fetches.
#include "accel/wide_bvh.h"
#include "accel/binned_sah_builder.h"
#include "accel/lbvh_builder.h"
#include "accel/wide_traverse.h"
#include "core/parallel.h"
#include "geometry/triangle.h"
#include "test_scenes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>
#include <type_traits>

using namespace toyrt;
using namespace toyrt::testing;

namespace {

constexpr uint32_t kLeaf = 8;  // a mesh's block width

Bvh sah_tree(const MeshData& m) {
  const PrimitiveBounds p = triangle_bounds(m);
  BinnedSahConfig config;
  config.leaf_without_search = kLeaf;
  return build_binned_sah(p.boxes.data(), p.boxes.size(), config);
}

Bvh lbvh_tree(const MeshData& m) {
  const PrimitiveBounds p = triangle_bounds(m);
  return build_lbvh(p.boxes.data(), p.boxes.size());
}

std::vector<MeshData> varied_meshes() {
  std::vector<MeshData> meshes;
  for (uint64_t seed = 1; seed <= 6; ++seed) meshes.push_back(triangle_soup(200 * seed * seed, 0.05f, seed));
  meshes.push_back(uv_sphere(40, 40, 1.0f, 0.15f));
  meshes.push_back(in_closed_room(uv_sphere(30, 30), 0.5f));
  meshes.push_back(slivers(3000, 7));
  meshes.push_back(triangle_soup(5, 0.3f, 9));  // one leaf: no wide node at all
  return meshes;
}

const CollapseMethod kMethods[] = {CollapseMethod::Greedy, CollapseMethod::Sah};

// Walks the wide tree from the root: counts how often each primitive slot and each node is
// reached, and checks node shapes as it goes.
void check_structure(const WideBvh& wide, const Bvh& bvh, uint32_t leaf_size) {
  std::vector<int> prim_seen(bvh.prim_ids.size(), 0), node_seen(wide.nodes.size(), 0);
  if (wide.nodes.empty()) {
    ASSERT_EQ(wide.root_leaf_count, bvh.prim_ids.size());
    return;
  }
  std::vector<uint32_t> stack{0};
  node_seen[0] = 1;
  while (!stack.empty()) {
    const WideNode& n = wide.nodes[stack.back()];
    stack.pop_back();
    int children = 0;
    for (int i = 0; i < kWidth; ++i) {
      if (n.bounds[0][i] > n.bounds[3][i]) continue;  // an empty slot
      ++children;
      if (n.count[i]) {
        EXPECT_LE(n.count[i], leaf_size);
        for (uint32_t k = 0; k < n.count[i]; ++k) ++prim_seen[n.child[i] + k];
      } else {
        ASSERT_LT(n.child[i], wide.nodes.size());
        ++node_seen[n.child[i]];
        stack.push_back(n.child[i]);
      }
    }
    EXPECT_GE(children, 2);  // a wide node of one child is a visit for nothing
  }
  for (size_t k = 0; k < prim_seen.size(); ++k) ASSERT_EQ(prim_seen[k], 1) << "primitive slot " << k;
  for (size_t k = 0; k < node_seen.size(); ++k) ASSERT_EQ(node_seen[k], 1) << "wide node " << k;
}

// A random point of `box` scaled about its centre by `spread`: the walk tests' rays start in a box
// three times the mesh's and aim at a point inside it.
Vec3 point_in(const BBox& box, float spread, std::mt19937& rng) {
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const Vec3 r(unit(rng), unit(rng), unit(rng));
  return box.center() + (r - 0.5f) * box.extent() * spread;
}

}  // namespace

TEST(WideBvh, EveryPrimitiveInExactlyOneLeafAndEveryNodeReachedOnce) {
  for (const MeshData& m : varied_meshes())
    for (const Bvh& bvh : {sah_tree(m), lbvh_tree(m)})
      for (CollapseMethod method : kMethods) {
        SCOPED_TRACE(m.triangles.size());
        check_structure(collapse(bvh, kLeaf, method), bvh, kLeaf);
      }
}

// The greedy collapse is one of the layouts the programme chooses among (each of its nodes holds
// at most 8 slots, each slot a collapsed leaf or a node of its own), so the programme's SAH cost
// is never above it.
TEST(WideBvh, SahCollapseCostsNoMoreThanTheGreedyOne) {
  int cheaper = 0, cases = 0;
  for (const MeshData& m : varied_meshes())
    for (const Bvh& bvh : {sah_tree(m), lbvh_tree(m)}) {
      const double greedy = wide_stats(collapse(bvh, kLeaf, CollapseMethod::Greedy), kLeaf).sah_cost;
      const double dp = wide_stats(collapse(bvh, kLeaf, CollapseMethod::Sah), kLeaf).sah_cost;
      EXPECT_LE(dp, greedy * (1.0 + 1e-5)) << m.triangles.size() << " triangles";  // float sums in the programme
      cheaper += dp < greedy * (1.0 - 1e-3);
      ++cases;
    }
  EXPECT_GT(cheaper, cases / 2);  // and on most trees strictly cheaper: the programme does something
}

// A complete binary tree of 64 equal, disjoint leaves of one primitive each (unit boxes along x,
// built by hand): the least cost is the root of 8 nodes of 8 leaves (9 nodes, all full), which
// both collapses find.
TEST(WideBvh, BalancedTreeOf64LeavesCollapsesToNineFullNodes) {
  Bvh bvh;
  // Heap order: node k's children are 2k + 1 and 2k + 2, leaves at 63..126 hold primitive k - 63.
  bvh.nodes.resize(127);
  for (int k = 126; k >= 0; --k) {
    Node& n = bvh.nodes[size_t(k)];
    if (k >= 63) {
      const float x = float(k - 63);
      n.set_bbox({{x, 0.0f, 0.0f}, {x + 0.5f, 0.5f, 0.5f}});
      n.first = uint32_t(k - 63);
      n.count = 1;
    } else {
      BBox b = bvh.nodes[size_t(2 * k + 1)].bbox();
      b.extend(bvh.nodes[size_t(2 * k + 2)].bbox());
      n.set_bbox(b);
      n.first = uint32_t(2 * k + 1);
      n.count = 0;
    }
  }
  for (uint32_t k = 0; k < 64; ++k) bvh.prim_ids.push_back(k);
  for (CollapseMethod method : kMethods) {
    const WideBvh wide = collapse(bvh, 1, method);
    const WideStats s = wide_stats(wide, 1);
    EXPECT_EQ(s.nodes, 9u);
    EXPECT_DOUBLE_EQ(s.children_per_node, 8.0);
    check_structure(wide, bvh, 1);
  }
}

// The programme runs in parallel over large subtrees; the layout must be the serial one's.
TEST(WideBvh, SahCollapseIsTheSameForAnyThreadCount) {
  const Bvh bvh = sah_tree(uv_sphere(200, 200, 1.0f, 0.15f));  // 80K triangles: parallel subtrees
  WideBvh one, many;
  run_with_threads(1, [&] { one = collapse(bvh, kLeaf, CollapseMethod::Sah); });
  run_with_threads(0, [&] { many = collapse(bvh, kLeaf, CollapseMethod::Sah); });
  ASSERT_EQ(one.nodes.size(), many.nodes.size());
  EXPECT_EQ(std::memcmp(one.nodes.data(), many.nodes.data(), one.nodes.size() * sizeof(WideNode)), 0);
}

// A dense model inside a closed room of 12 wall triangles (the last 12 of the mesh): the SAH
// builder files walls along a chain of room-sized binary nodes, and an any-hit walk tests the
// root's children largest first. Under either method the root's largest slot must be a leaf of
// walls only, so a shadow ray blocked by one of them is decided by the first leaf it tests
// instead of after a second node. The 1M-triangle sphere of bench_trace's closed room: without
// kChainVisitWeight the programme kept the chain as a wide node of its own there, and the root's
// largest child was an interior node (smaller spheres, 20K to 720K triangles, happened to pass
// either way).
TEST(WideBvh, RootsLargestChildIsALeafOfWallsInAClosedRoom) {
  const MeshData m = in_closed_room(uv_sphere(708, 708, 1.0f, 0.15f), 0.5f);
  const uint32_t first_wall = uint32_t(m.triangles.size() - 12);
  const Bvh bvh = sah_tree(m);
  for (CollapseMethod method : kMethods) {
    SCOPED_TRACE(::testing::Message() << m.triangles.size() << " triangles, method " << int(method));
    const WideBvh wide = collapse(bvh, kLeaf, method);
    ASSERT_FALSE(wide.nodes.empty());
    const WideNode& root = wide.nodes[0];
    int largest = -1;
    float largest_area = -1.0f;
    for (int i = 0; i < kWidth; ++i) {
      if (!root.used(i)) continue;
      const float area = root.box(i).half_area();
      if (area > largest_area) {
        largest = i;
        largest_area = area;
      }
    }
    EXPECT_EQ(largest, 0);  // slot order is decreasing area: the any-hit walk's first
    ASSERT_GT(root.count[0], 0u) << "the root's largest child is an interior node";
    for (uint32_t k = 0; k < root.count[0]; ++k) EXPECT_GE(bvh.prim_ids[root.child[0] + k], first_wall);
  }
}

// closest_hit_wide<true> visits the node on top of the stack before testing a leaf it has just
// chosen (so that the leaf's lines arrive meanwhile): the leaves must still be tested in the same
// order, and every ray must find the same nearest triangle at the same distance. (The walks may
// differ where one of that node's children is entered within rounding beyond the leaf's hit, which
// these fixed rays do not meet.) The overlap shows in the order of the walk's calls: the node's
// leaf children are requested (prefetch_leaf) before the leaf is tested, which the plain walk does
// after; some rays must show it, or the overlapped form never ran.
TEST(WideTraverse, OverlappedLeafFetchesTestTheSameLeavesInTheSameOrder) {
  size_t rays = 0, rays_through_several_leaves = 0, hits = 0, overlapped = 0;
  for (const MeshData& m : varied_meshes()) {
    const Bvh bvh = sah_tree(m);
    const WideBvh wide = collapse(bvh, kLeaf, CollapseMethod::Sah);
    const BBox box = bounds_of(m);
    std::mt19937 rng(11);
    for (int k = 0; k < 2000; ++k) {
      const Vec3 org = point_in(box, 3.0f, rng), dir = point_in(box, 1.0f, rng) - org;
      const WatertightRay tri_ray = make_watertight_ray(org, dir);
      // calls: a leaf tested as its first slot, a leaf requested as -1 - its first slot
      auto walk = [&](auto overlap, std::vector<int64_t>& calls, int64_t& prim) {
        float tfar = kInfinity;
        prim = -1;
        const bool found = closest_hit_wide<decltype(overlap)::value>(
            wide, make_ray_box_data(org, dir), 0.0f, tfar,
            [&](uint32_t first, uint32_t count, float& t_max) {
              calls.push_back(first);
              bool hit = false;
              for (uint32_t j = first; j < first + count; ++j) {
                const Triangle& tri = m.triangles[bvh.prim_ids[j]];
                float t, u, v;
                if (intersect_triangle(tri_ray, m.vertices[tri[0]], m.vertices[tri[1]], m.vertices[tri[2]], 0.0f, t_max,
                                       t, u, v)) {
                  t_max = t;
                  prim = bvh.prim_ids[j];
                  hit = true;
                }
              }
              return hit;
            },
            [&](uint32_t first, uint32_t) { calls.push_back(-1 - int64_t(first)); });
        return found ? tfar : -1.0f;
      };
      std::vector<int64_t> plain_calls, overlapped_calls;
      int64_t plain_prim, overlapped_prim;
      const float plain_t = walk(std::false_type{}, plain_calls, plain_prim);
      const float overlapped_t = walk(std::true_type{}, overlapped_calls, overlapped_prim);
      auto tested = [](const std::vector<int64_t>& calls) {
        std::vector<int64_t> leaves;
        for (int64_t c : calls)
          if (c >= 0) leaves.push_back(c);
        return leaves;
      };
      const std::vector<int64_t> plain_order = tested(plain_calls);
      ASSERT_EQ(plain_order, tested(overlapped_calls)) << "ray " << k;
      ASSERT_EQ(plain_t, overlapped_t) << "ray " << k;
      ASSERT_EQ(plain_prim, overlapped_prim) << "ray " << k;
      ++rays;
      rays_through_several_leaves += plain_order.size() > 1;
      hits += plain_prim >= 0;
      overlapped += plain_calls != overlapped_calls;
    }
  }
  EXPECT_GT(rays_through_several_leaves, rays / 2);
  EXPECT_GT(hits, rays / 4);
  EXPECT_GT(overlapped, rays / 20);
}

// any_hit_wide<true> keeps one leaf in flight: a leaf reached is requested (prefetch_leaf) and
// tested one step later, but for a leaf that a ray's first two visits (the root and one of its
// children) enter first. Its answer must be the plain walk's and a loop over every triangle's, on
// segments short enough that some rays are blocked and others not; a ray nothing blocks must test
// the same leaves as the plain walk, each once, each after its request but for those near the top.
TEST(WideTraverse, AnyHitWithALeafInFlightGivesThePlainWalksAnswer) {
  size_t rays = 0, blocked = 0, open_through_several_leaves = 0, with_leaves_in_flight = 0;
  for (const MeshData& m : varied_meshes()) {
    const Bvh bvh = sah_tree(m);
    const WideBvh wide = collapse(bvh, kLeaf, CollapseMethod::Sah);
    // Leaves the walk may test without a request: the root's, and its child nodes'.
    std::vector<int64_t> near_top;
    if (wide.nodes.empty()) near_top.push_back(wide.root_leaf_first);  // one leaf: tested at once
    for (int i = 0; i < kWidth && !wide.nodes.empty(); ++i) {
      const WideNode& root = wide.nodes[0];
      if (!root.used(i)) continue;
      if (root.count[i] != 0) {
        near_top.push_back(root.child[i]);
        continue;
      }
      const WideNode& n = wide.nodes[root.child[i]];
      for (int j = 0; j < kWidth; ++j)
        if (n.used(j) && n.count[j] != 0) near_top.push_back(n.child[j]);
    }
    const BBox box = bounds_of(m);
    std::mt19937 rng(12);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    for (int k = 0; k < 2000; ++k) {
      const Vec3 org = point_in(box, 3.0f, rng), dir = point_in(box, 1.0f, rng) - org;
      // The segment ends anywhere from the origin to twice as far as the point inside the box that
      // dir aims at, so some rays are blocked and others are not.
      const float tfar = 2.0f * unit(rng);
      const WatertightRay tri_ray = make_watertight_ray(org, dir);
      auto hits_triangle = [&](uint32_t prim) {
        const Triangle& tri = m.triangles[prim];
        float t, u, v;
        return intersect_triangle(tri_ray, m.vertices[tri[0]], m.vertices[tri[1]], m.vertices[tri[2]], 0.0f, tfar, t, u,
                                  v);
      };
      // calls: a leaf tested as its first slot, a leaf requested as -1 - its first slot
      auto walk = [&](auto overlap, std::vector<int64_t>& calls) {
        return any_hit_wide<decltype(overlap)::value>(
            wide, make_ray_box_data(org, dir), 0.0f, tfar,
            [&](uint32_t first, uint32_t count, float) {
              calls.push_back(first);
              for (uint32_t j = first; j < first + count; ++j)
                if (hits_triangle(bvh.prim_ids[j])) return true;
              return false;
            },
            [&](uint32_t first, uint32_t) { calls.push_back(-1 - int64_t(first)); });
      };
      bool expected = false;
      for (uint32_t i = 0; i < m.triangles.size() && !expected; ++i) expected = hits_triangle(i);
      std::vector<int64_t> plain_calls, in_flight_calls;
      ASSERT_EQ(walk(std::false_type{}, plain_calls), expected) << "ray " << k;
      ASSERT_EQ(walk(std::true_type{}, in_flight_calls), expected) << "ray " << k;
      ++rays;
      blocked += expected;
      if (expected) continue;
      std::vector<int64_t> tested, requested;
      for (int64_t c : in_flight_calls) {
        if (c < 0) {
          requested.push_back(-1 - c);
        } else {
          const bool at_top = std::find(near_top.begin(), near_top.end(), c) != near_top.end();
          ASSERT_TRUE(at_top || std::find(requested.begin(), requested.end(), c) != requested.end())
              << "tested before its request, ray " << k;
          tested.push_back(c);
        }
      }
      std::sort(tested.begin(), tested.end());
      ASSERT_EQ(std::adjacent_find(tested.begin(), tested.end()), tested.end()) << "a leaf tested twice, ray " << k;
      std::sort(plain_calls.begin(), plain_calls.end());
      ASSERT_EQ(tested, plain_calls) << "ray " << k;
      open_through_several_leaves += tested.size() > 1;
      with_leaves_in_flight += !requested.empty();
    }
  }
  EXPECT_GT(blocked, rays / 10);
  EXPECT_LT(blocked, rays * 9 / 10);
  EXPECT_GT(open_through_several_leaves, rays / 10);
  EXPECT_GT(with_leaves_in_flight, rays / 10);
}
