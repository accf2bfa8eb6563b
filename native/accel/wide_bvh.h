// The traversal layout: the binary Bvh collapsed into nodes of up to kWidth children whose boxes
// are stored side by side (one array per bound), so one traversal step tests all of them with
// SIMD instructions. Builders keep producing the binary Bvh (simple to build, check and share
// with the LBVH kernels); this is derived from it at commit time.
#pragma once

#include "accel/bvh.h"
#include "accel/lbvh_layout.h"
#include "core/huge_page_allocator.h"

#include <functional>
#include <vector>

namespace toyrt {

// 8 lanes: one AVX register of boxes per bound (and two SSE registers where AVX is absent).
inline constexpr int kWidth = 8;

struct alignas(64) WideNode {
  // Child boxes by bound; an unused slot holds an empty box (lo = +inf, hi = -inf) that no ray
  // enters. Indexed [0..5] = lo.x, lo.y, lo.z, hi.x, hi.y, hi.z, like Node::bounds.
  float bounds[6][kWidth];
  // Interior child (count == 0): index of its WideNode. Leaf child (count > 0): first primitive
  // slot, as in Node.
  uint32_t child[kWidth];
  uint32_t count[kWidth];

  // Whether slot i holds a child (an unused slot's box is empty).
  bool used(int i) const { return bounds[0][i] <= bounds[3][i]; }
  // Slot i's box.
  BBox box(int i) const {
    BBox b;
    b.lo = {bounds[0][i], bounds[1][i], bounds[2][i]};
    b.hi = {bounds[3][i], bounds[4][i], bounds[5][i]};
    return b;
  }
  void set_box(int i, const BBox& b) {
    for (int a = 0; a < 3; ++a) {
      bounds[a][i] = b.lo[a];
      bounds[a + 3][i] = b.hi[a];
    }
  }
};
static_assert(sizeof(WideNode) == 256, "WideNode: 4 cache lines for 8 children");

struct WideBvh {
  // Root at 0 (absent for an empty tree); in huge pages, as traversal reads them at random.
  std::vector<WideNode, HugePageAllocator<WideNode>> nodes;
  // When the whole tree is a single leaf it has no wide node: the leaf's range is kept here.
  uint32_t root_leaf_first = 0, root_leaf_count = 0;
  bool empty() const { return nodes.empty() && root_leaf_count == 0; }
};

// What a mesh traces: a builder's tree in the wide layout, and the primitive order its leaves
// index (a leaf child's `child` is its first slot in prim_ids).
struct WideBuild {
  WideBvh wide;
  std::vector<uint32_t> prim_ids;
  // The builder left the boxes to the caller (BuildConfig::leaf_boxes_by_caller): every used slot
  // holds a stand-in box (a point, so that used() holds), and the slots are in build order. The
  // caller writes each leaf slot's box, then calls complete_wide_boxes().
  bool boxes_pending = false;
};

// Finishes a build with boxes_pending: every subtree before its parent, leaves(i) writing node
// i's leaf slots' boxes (Mesh::finish copies their triangles into blocks there), then node i's
// interior slots bounded by their children, just finished and still in cache, and its slots put
// in any_hit_order. The subtrees below the top three branching levels run as parallel tasks, each
// ending with task_end() on its thread (Mesh::finish fences its streamed stores there); what runs
// on the calling thread outside them (the top nodes' own leaves) is the caller's to finish after
// the call. Writes the same boxes and order on any thread count.
void complete_wide_boxes(
    WideBvh& bvh, const std::function<void(uint32_t node)>& leaves, const std::function<void()>& task_end = [] {});

// A node's used slots moved into any_hit_order (below), the order collapse() gives them.
void sort_slots(WideNode& node);

// How collapse() chooses which binary nodes a wide node opens.
enum class CollapseMethod {
  // Opens the largest (by surface area) interior child until kWidth children are held.
  Greedy,
  // A bottom-up dynamic programme over the binary tree (after Ylitie, Karras and Laine 2017,
  // "Efficient Incoherent Ray Traversal on GPUs Through Compressed Wide BVHs", section 4): for
  // every binary node and every budget of 1..kWidth slots, the least SAH cost of its subtree
  // held in that many slots, then the decisions read out top-down. Greedy fills the top of each
  // node and leaves narrow nodes near the bottom (a subtree of 12-24 triangles as a node of two
  // or three leaves); the programme spends slots where they save the most node visits.
  Sah,
};

// The SAH weights of a wide node visit and of one triangle block test (8 box tests against 8
// triangle tests; the block's weight is an estimate). While every leaf is a collapsed subtree of
// at most leaf_size primitives the leaves cost the same in every layout, and 1.0, 1.5 and 2.5
// gave the same trees (docs/trace-speed.md, eighteenth session).
inline constexpr double kWideNodeCost = 1.0, kBlockCost = 1.5;

// The SAH programme's weight on a visit to a binary node whose box is its parent's (to 0.1 % of
// the half area) when it becomes a wide node of its own. A binary SAH tree files large primitives
// whose boxes span the scene (a room's walls) along a chain of such nodes, each peeling off a
// slice of the model inside. Opening the chain into one wide node brings the walls' leaf up to
// where the any-hit walk, which tests children largest first, meets it first; the plain SAH cost,
// which models a walk that visits every box it enters, did not: the 1M-triangle sphere in a
// closed room traced its wall-blocked shadow rays 15-20 % slower under the programme than under
// the greedy collapse (docs/trace-speed.md). 2 opens that chain and leaves trees without such
// links alone (the bumpy spheres: same node counts, SAH costs and instructions a ray).
inline constexpr double kChainVisitWeight = 2.0;

// Collapses a binary Bvh into wide nodes. A subtree of at most `leaf_size` primitives becomes
// one leaf (a subtree's primitives are contiguous in prim_ids, since builders partition
// top-down), so small leaves do not leave wide nodes half empty.
WideBvh collapse(const Bvh& bvh, uint32_t leaf_size = 1, CollapseMethod method = CollapseMethod::Sah);
// The same from the LBVH kernels' radix tree (sorted leaf k = prim_ids slot k): the same wide
// tree as collapsing that tree's flat Bvh (to_bvh), without writing the 2n - 1 flat nodes.
WideBvh collapse(const LbvhTree& tree, uint32_t leaf_size = 1, CollapseMethod method = CollapseMethod::Sah);

// The order every builder gives a wide node's children: by decreasing surface area, stably. The
// any-hit walk visits them in slot order, and a large box is the likelier to block a shadow ray
// (a wall beside a dense model: found at once instead of after the model's subtrees); the
// closest-hit walk sorts by distance and ignores it. Fills order[0..n) with 0..n-1 so ordered
// (a NaN area, which no finite box has, ranks as 0).
void any_hit_order(const BBox* boxes, int n, int order[kWidth]);

struct WideStats {
  size_t nodes = 0;
  double children_per_node = 0.0;
  // Expected cost of a random ray (probability of a box = its area over the root's): kWideNodeCost
  // a wide node visit, kBlockCost a block of up to `block_width` primitives in a leaf.
  double sah_cost = 0.0;
};
WideStats wide_stats(const WideBvh& wide, uint32_t block_width);

}  // namespace toyrt
