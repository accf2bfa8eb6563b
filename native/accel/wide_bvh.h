// The traversal layout: the binary Bvh collapsed into nodes of up to kWidth children whose boxes
// are stored side by side (one array per bound), so one traversal step tests all of them with
// SIMD instructions. Builders keep producing the binary Bvh (simple to build, check and share
// with the LBVH kernels); this is derived from it at commit time.
#pragma once

#include "accel/bvh.h"
#include "core/huge_page_allocator.h"

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
};
static_assert(sizeof(WideNode) == 256, "WideNode: 4 cache lines for 8 children");

struct WideBvh {
  // Root at 0 (absent for an empty tree); in huge pages, as traversal reads them at random.
  std::vector<WideNode, HugePageAllocator<WideNode>> nodes;
  // When the whole tree is a single leaf it has no wide node: the leaf's range is kept here.
  uint32_t root_leaf_first = 0, root_leaf_count = 0;
  bool empty() const { return nodes.empty() && root_leaf_count == 0; }
};

// Collapses a binary Bvh: each wide node takes the children of a binary node and keeps opening
// the largest (by surface area) interior child among them until it holds kWidth children. A
// subtree of at most `leaf_size` primitives becomes one leaf (a subtree's primitives are
// contiguous in prim_ids, since builders partition top-down), so small leaves do not leave wide
// nodes half empty.
WideBvh collapse(const Bvh& bvh, uint32_t leaf_size = 1);

}  // namespace toyrt
