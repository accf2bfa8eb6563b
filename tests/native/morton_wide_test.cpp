// build_morton_wide(): the LBVH built on the host, top down from sorted Morton codes straight to
// wide nodes. Its order is the LBVH reference's (same codes, stable sort), every primitive sits in
// exactly one leaf whose box holds it, every box holds what is under it, and the layout does not
// depend on the thread count.
#include "accel/lbvh_builder.h"
#include "accel/morton_wide_builder.h"
#include "core/parallel.h"
#include "test_scenes.h"

#include <gtest/gtest.h>

#include <algorithm>

#include <cstring>

using namespace toyrt;
using namespace toyrt::testing;

namespace {

constexpr uint32_t kLeaf = 8;  // a mesh's block width

std::vector<MeshData> varied_meshes() {
  std::vector<MeshData> meshes;
  for (uint64_t seed = 1; seed <= 4; ++seed) meshes.push_back(triangle_soup(300 * seed * seed, 0.05f, seed));
  meshes.push_back(uv_sphere(120, 120, 1.0f, 0.15f));  // 28,560 triangles
  meshes.push_back(uv_sphere(300, 300, 1.0f, 0.15f));  // 179,400: subtrees of 22K handed on as tasks
  meshes.push_back(in_closed_room(uv_sphere(30, 30), 0.5f));
  meshes.push_back(slivers(3000, 7));
  meshes.push_back(triangle_soup(5, 0.3f, 9));  // one leaf: no wide node at all
  // Flat but for denormal heights: the centres' z extent is denormal, its scale infinite, so the
  // z cells are 0 * inf = NaN (clamped to 0) at the bottom and inf (clamped to the top cell) above
  // it, in the codes' vector path and its scalar tail alike (2,001 primitives: 2,000 by eights).
  MeshData flat = triangle_soup(2001, 0.05f, 11);
  for (size_t i = 0; i < flat.vertices.size(); ++i) flat.vertices[i].z = float(i % 3) * 1e-41f;
  meshes.push_back(flat);
  // 200,000 triangles in the unit cube and one far off: the cluster shares the codes' top 8
  // bits, one sort bucket too large for the in-cache sort (the parallel radix sort's path). At
  // 10 units the cluster's codes differ in all three of that sort's 8-bit digits; at 100 in the
  // lower two only, so one pass is skipped and the result is copied from the other buffer.
  for (const float distance : {10.0f, 100.0f}) {
    MeshData crowded = triangle_soup(200000, 0.01f, 5);
    const uint32_t far = uint32_t(crowded.vertices.size());
    crowded.vertices.push_back(Vec3(distance));
    crowded.vertices.push_back(Vec3(distance + 1.0f, distance, distance));
    crowded.vertices.push_back(Vec3(distance, distance + 1.0f, distance + 0.5f));
    crowded.triangles.push_back({far, far + 1, far + 2});
    meshes.push_back(crowded);
  }
  MeshData same;  // 100,000 copies of one triangle: every code equal, tasks of 12,500
  same.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  same.triangles.assign(100000, Triangle(0, 1, 2));
  meshes.push_back(same);
  return meshes;
}

bool holds(const BBox& outer, const BBox& inner) {
  for (int a = 0; a < 3; ++a)
    if (inner.lo[a] < outer.lo[a] || inner.hi[a] > outer.hi[a]) return false;
  return true;
}

// Walks the tree from the root: each slot's box holds its primitives' boxes (a leaf) or every
// box of the node it points to; each primitive slot and each node is reached exactly once; no
// node has fewer than two children. Returns the deepest node's depth.
int check_tree(const WideBuild& built, const std::vector<BBox>& boxes, uint32_t leaf_size) {
  const WideBvh& wide = built.wide;
  std::vector<int> prim_seen(built.prim_ids.size(), 0), node_seen(wide.nodes.size(), 0);
  if (wide.nodes.empty()) {
    EXPECT_EQ(wide.root_leaf_count, built.prim_ids.size());
    return 0;
  }
  std::vector<std::pair<uint32_t, int>> stack{{0u, 1}};
  node_seen[0] = 1;
  int deepest = 0;
  while (!stack.empty()) {
    const auto [index, depth] = stack.back();
    stack.pop_back();
    deepest = std::max(deepest, depth);
    const WideNode& n = wide.nodes[index];
    int children = 0;
    for (int i = 0; i < kWidth; ++i) {
      if (!n.used(i)) continue;
      ++children;
      if (n.count[i]) {
        EXPECT_LE(n.count[i], leaf_size);
        for (uint32_t k = 0; k < n.count[i]; ++k) {
          ++prim_seen[n.child[i] + k];
          EXPECT_TRUE(holds(n.box(i), boxes[built.prim_ids[n.child[i] + k]])) << "leaf slot " << i;
        }
      } else {
        EXPECT_LT(n.child[i], wide.nodes.size());
        if (n.child[i] >= wide.nodes.size()) continue;
        const WideNode& c = wide.nodes[n.child[i]];
        for (int k = 0; k < kWidth; ++k) {
          if (c.used(k)) {
            EXPECT_TRUE(holds(n.box(i), c.box(k))) << "node " << index << " slot " << i;
          }
        }
        ++node_seen[n.child[i]];
        stack.push_back({n.child[i], depth + 1});
      }
    }
    EXPECT_GE(children, 2);
  }
  for (size_t k = 0; k < prim_seen.size(); ++k) EXPECT_EQ(prim_seen[k], 1) << "primitive slot " << k;
  for (size_t k = 0; k < node_seen.size(); ++k) EXPECT_EQ(node_seen[k], 1) << "wide node " << k;
  return deepest;
}

}  // namespace

TEST(MortonWide, OrderIsTheLbvhReferencesForThirtyBitCodes) {
  for (const MeshData& m : varied_meshes()) {
    const PrimitiveBounds p = triangle_bounds(m);
    const WideBuild built = build_morton_wide(p.boxes.data(), p.boxes.size(), kLeaf);
    const LbvhHierarchy reference =
        build_lbvh_hierarchy_reference(p.boxes.data(), p.boxes.size(), LbvhConfig{MortonBits::k30});
    EXPECT_EQ(built.prim_ids, reference.values) << m.triangles.size() << " triangles";
  }
}

TEST(MortonWide, EveryPrimitiveInOneLeafAndEveryBoxHoldsWhatIsUnderIt) {
  for (const uint32_t leaf : {1u, 4u, kLeaf}) {
    for (const MeshData& m : varied_meshes()) {
      SCOPED_TRACE(std::to_string(m.triangles.size()) + " triangles, leaves of " + std::to_string(leaf));
      const PrimitiveBounds p = triangle_bounds(m);
      const int depth = check_tree(build_morton_wide(p.boxes.data(), p.boxes.size(), leaf), p.boxes, leaf);
      // Equal codes split in the middle, so even 100,000 equal triangles stay shallow.
      EXPECT_LE(depth, 16);
    }
  }
}

TEST(MortonWide, BoxesHoldWhatIsUnderThemWhenTasksHandOnTasks) {
  // 718,800 triangles: the root's children (about 90K) hand theirs (about 11K) on in turn, so
  // boxes are patched through two levels of tasks.
  const MeshData m = uv_sphere(600, 600, 1.0f, 0.15f);
  const PrimitiveBounds p = triangle_bounds(m);
  check_tree(build_morton_wide(p.boxes.data(), p.boxes.size(), kLeaf), p.boxes, kLeaf);
}

TEST(MortonWide, SameLayoutOnAnyThreadCount) {
  // 179,400 triangles: two levels of tasks of up to 8,192; 9,940: tasks of up to a 16th of the
  // mesh, and the passes in chunks of 2,048 (a small mesh's own sizes, core/parallel.h).
  for (const int rings : {300, 71}) {
    const MeshData m = uv_sphere(rings, rings, 1.0f, 0.1f);
    SCOPED_TRACE(std::to_string(m.triangles.size()) + " triangles");
    const PrimitiveBounds p = triangle_bounds(m);
    auto build = [&](int threads) {
      WideBuild built;
      run_with_threads(threads, [&] { built = build_morton_wide(p.boxes.data(), p.boxes.size(), kLeaf); });
      return built;
    };
    const WideBuild one = build(1);
    for (const int threads : {2, 0}) {
      const WideBuild other = build(threads);
      EXPECT_EQ(one.prim_ids, other.prim_ids);
      ASSERT_EQ(one.wide.nodes.size(), other.wide.nodes.size());
      EXPECT_EQ(0,
                std::memcmp(one.wide.nodes.data(), other.wide.nodes.data(), one.wide.nodes.size() * sizeof(WideNode)));
    }
  }
}

TEST(MortonWide, NoPrimitivesNoTree) {
  const WideBuild built = build_morton_wide(nullptr, 0, kLeaf);
  EXPECT_TRUE(built.wide.empty());
  EXPECT_TRUE(built.prim_ids.empty());
}

TEST(MortonWide, LeavesBoundedByTheCallerGiveTheSameTree) {
  // Mesh::finish bounds the leaves as it copies their triangles (BuildConfig::leaf_boxes_by_caller)
  // and complete_wide_boxes() makes the rest, subtrees as parallel tasks: node for node, the tree
  // the builder makes itself, boxes, slot order and children alike. 718,800 triangles: boxes
  // through two levels of the builder's tasks.
  for (const int rings : {600, 71, 8}) {  // 71 and 8: small enough to be bounded by the builder
    const MeshData m = uv_sphere(rings, rings, 1.0f, 0.15f);
    SCOPED_TRACE(std::to_string(m.triangles.size()) + " triangles");
    const PrimitiveBounds p = triangle_bounds(m);
    const WideBuild eager = build_morton_wide(p.boxes.data(), p.boxes.size(), kLeaf);
    WideBuild deferred = build_morton_wide(p.boxes.data(), p.boxes.size(), kLeaf, false);
    EXPECT_FALSE(eager.boxes_pending);
    ASSERT_EQ(deferred.boxes_pending, rings == 600);
    std::vector<int> visits(deferred.wide.nodes.size(), 0);
    complete_wide_boxes(deferred.wide, [&](uint32_t i) {
      ++visits[i];
      WideNode& n = deferred.wide.nodes[i];
      for (int k = 0; k < kWidth; ++k) {
        if (n.count[k] == 0) continue;
        BBox b;
        for (uint32_t j = n.child[k]; j < n.child[k] + n.count[k]; ++j) b.extend(p.boxes[deferred.prim_ids[j]]);
        n.set_box(k, b);
      }
    });
    EXPECT_EQ(std::count(visits.begin(), visits.end(), 1), std::ptrdiff_t(visits.size()));  // each node once
    EXPECT_EQ(eager.prim_ids, deferred.prim_ids);
    ASSERT_EQ(eager.wide.nodes.size(), deferred.wide.nodes.size());
    EXPECT_EQ(0, std::memcmp(eager.wide.nodes.data(), deferred.wide.nodes.data(),
                             eager.wide.nodes.size() * sizeof(WideNode)));
  }
}
