// One node of the flat binary BVH: 32 bytes, two per cache line, so a traversal step that
// reads both children of a node touches a single line.
#pragma once

#include "core/bbox.h"

#include <cstdint>

namespace toyrt {

struct Node {
  // {lo.x, lo.y, lo.z, hi.x, hi.y, hi.z}: indexed by RayBoxData::near/far in the slab test.
  float bounds[6];
  // Interior node (count == 0): index of the left child; the right child is first + 1.
  // Leaf (count > 0): index of the first of `count` primitives in Bvh::prim_ids.
  uint32_t first;
  uint32_t count;

  bool is_leaf() const { return count != 0; }
  BBox bbox() const { return {{bounds[0], bounds[1], bounds[2]}, {bounds[3], bounds[4], bounds[5]}}; }
  void set_bbox(const BBox& b) {
    bounds[0] = b.lo.x;
    bounds[1] = b.lo.y;
    bounds[2] = b.lo.z;
    bounds[3] = b.hi.x;
    bounds[4] = b.hi.y;
    bounds[5] = b.hi.z;
  }
};
static_assert(sizeof(Node) == 32, "Node must stay 32 bytes: two per cache line");

}  // namespace toyrt
