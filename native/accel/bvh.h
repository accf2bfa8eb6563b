// The bounding volume hierarchy as plain data: a flat node array (root at 0, children of a node
// adjacent) and the primitive order its leaves index. Builders produce it (binned_sah_builder.h,
// and the LBVH in kernels/), traversal reads it (traverse.h); nothing else owns it.
#pragma once

#include "accel/node.h"
#include "core/huge_page_allocator.h"

#include <string>
#include <utility>
#include <vector>

namespace toyrt {

// Traversal keeps an explicit stack of this many entries; builders never exceed this depth.
inline constexpr int kMaxBvhDepth = 96;

// The prim_ids slots under a node: first, first + 1, ..., first + count - 1.
struct SlotRange {
  uint32_t first, count;
};

struct Bvh {
  // Huge pages, not zeroed on resize (core/huge_page_allocator.h): the LBVH's two million nodes at
  // 1M triangles were zeroed on one thread before its kernel wrote every one of them.
  std::vector<Node, HugePageAllocator<Node>> nodes;
  std::vector<uint32_t> prim_ids;  // leaf slots -> primitive index in the builder's input
  // (first, count) of the prim_ids slots under each node, when a builder has them at no cost (the
  // LBVH kernels write them); empty otherwise, and collapse() derives them by a walk.
  std::vector<SlotRange, HugePageAllocator<SlotRange>> ranges;

  bool empty() const { return nodes.empty(); }

  // Expected cost of a random ray (surface area heuristic, traversal and intersection cost 1):
  // the figure of merit builders are compared by.
  double sah_cost(double traversal_cost = 1.0, double intersection_cost = 1.0) const;
  int depth() const;
  size_t leaf_count() const;

  // Checks the structural invariants against the primitives' bounds: every primitive in exactly
  // one leaf, every child box inside its parent, every primitive inside its leaf, depth within
  // kMaxBvhDepth. Returns an empty string when all hold, else what failed.
  std::string validate(const BBox* prim_bounds, size_t prim_count) const;
};

}  // namespace toyrt
