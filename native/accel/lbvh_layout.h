// The data the LBVH kernels (kernels/lbvh.cl) and the host share, byte by byte. The kernel file
// declares the same struct; the asserts below keep the host side honest.
//
//   LbvhNode, 32 bytes, one per internal node (n - 1 of them for n primitives): node g splits
//   between sorted leaves g and g + 1; the root is the one whose range is every leaf (`root`)
//     bytes  0-11  float lo[3]   box minimum      (all written by build_hierarchy)
//     bytes 12-15  int   left    child: >= 0 an internal node, < 0 the leaf ~left
//     bytes 16-27  float hi[3]   box maximum
//     bytes 28-31  int   right   child, encoded like left
//   A leaf k is the k-th primitive in Morton order: values[k] is its index in the input.
//
//   Node (native/accel/node.h), 32 bytes, the flat BVH the last kernel writes: 2n - 1 of them
//     bytes  0-23  float bounds[6]  lo.xyz, hi.xyz
//     bytes 24-27  uint  first      interior: left child index (right = first + 1); leaf: sorted slot
//     bytes 28-31  uint  count      0 interior, 1 leaf
//   The children of internal node g sit at 1 + 2g and 2 + 2g; the root at 0.
//
//   Other buffers: prim_bounds float[6n] (lo.xyz, hi.xyz) in input order;
//   keys uint[n] for 30-bit codes, ulong[n] for 63-bit ones (Morton codes, sorted in place of the
//   input order), values uint[n] (sorted slot -> input index); range uint2[n - 1] (first and last
//   sorted leaf under node g; written only for the flat nodes); ends int[n - 1] (zeroed;
//   build_hierarchy's meeting points);
//   root int[1].
#pragma once

#include <cstddef>
#include <cstdint>

#include "accel/node.h"

namespace toyrt {

struct LbvhNode {
  float lo[3];
  int32_t left;
  float hi[3];
  int32_t right;
};
static_assert(sizeof(LbvhNode) == 32, "LbvhNode must match kernels/lbvh.cl: 32 bytes");
static_assert(offsetof(LbvhNode, lo) == 0 && offsetof(LbvhNode, left) == 12, "LbvhNode layout: lo, left");
static_assert(offsetof(LbvhNode, hi) == 16 && offsetof(LbvhNode, right) == 28, "LbvhNode layout: hi, right");
static_assert(offsetof(Node, bounds) == 0 && offsetof(Node, first) == 24 && offsetof(Node, count) == 28,
              "Node must match BvhNode in kernels/lbvh.cl");
static_assert(sizeof(float) == 4 && sizeof(uint64_t) == 8, "OpenCL float is 4 bytes, ulong 8");

// The radix tree as the kernels leave it after build_hierarchy, which collapse()
// (accel/wide_bvh.h) reads in place: no flat Bvh in between.
struct LbvhTree {
  const LbvhNode* nodes = nullptr;    // leaves - 1 internal nodes, by split position, boxes filled
  uint32_t root = 0;                  // the internal node over every leaf (leaves >= 2)
  const BBox* prim_bounds = nullptr;  // the primitives' boxes in input order (leaf k's: prim_bounds[order[k]])
  const uint32_t* order = nullptr;    // sorted leaf -> input index (the sort's values)
  size_t leaves = 0;
};

// Morton code precision: 10 bits per axis (30-bit codes) or 21 (63-bit codes).
enum class MortonBits : uint32_t { k30 = 10, k63 = 21 };

}  // namespace toyrt
