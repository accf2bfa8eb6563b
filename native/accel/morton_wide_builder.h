// The LBVH on the host: primitives sorted along the 30-bit Morton curve of their box centres (the
// codes and order of the OpenCL build), then wide nodes built top down straight from the sorted
// codes, as Embree's Morton builder does: a range is split where the highest bit in which its
// codes differ turns to 1, and a wide node keeps splitting its most populous child until it holds
// kWidth children. No binary tree is written and nothing is collapsed: at a million triangles the
// OpenCL build's radix tree (32 bytes a primitive) and the collapse that reads it back were most
// of the LBVH commit on a CPU device. The tree is coarser than the collapsed radix tree's (the
// children are chosen by count, not by surface area) and is built in a fraction of the time.
#pragma once

#include "accel/wide_bvh.h"

namespace toyrt {

// Builds over `count` primitives given their boxes (a primitive's centre is its box's), with
// leaves of up to leaf_size primitives, on the calling thread's TBB arena. The same tree and
// layout on any thread count. prim_ids is the sorted order (the LBVH reference's, for 30-bit codes).
// Without leaf_boxes, where the boxes outgrow a core's L2 cache, the leaves are not bounded (their
// boxes are read at random, by sorted code: 9 % of the 1M-triangle LBVH commit), nor anything
// above them: WideBuild::boxes_pending, and the caller bounds the leaves in complete_wide_boxes().
WideBuild build_morton_wide(const BBox* prim_bounds, size_t count, uint32_t leaf_size, bool leaf_boxes = true);

}  // namespace toyrt
