// The walk of the multi-hit queries over a WideBvh: every leaf whose box the ray's segment
// reaches, in no particular order. Tracing's traverse_wide (accel/wide_traverse.h) sorts the
// children it enters by distance so that a nearer hit can prune the rest; a count prunes nothing,
// so here the children are stacked as the slab test finds them. The walk is bound by memory
// latency: a node is four cache lines (the boxes, then the child ids) and a triangle block five,
// so every line of each stacked node and of each stacked leaf's first block is asked for
// (prefetched) when it is stacked, not one line when it is popped (docs/queries.md: 1.4x the
// counts at 327K triangles).
#pragma once

#include "accel/wide_traverse.h"
#include "geometry/triangle_block.h"

namespace toyrt::queries {

// Asks for every cache line of an object that the walk will read whole. (Inlined by force: a call
// to a function that only prefetches is one GCC may drop as pure.)
[[gnu::always_inline]] inline void prefetch_lines(const void* p, size_t bytes) {
  for (size_t k = 0; k < bytes; k += 64) __builtin_prefetch(static_cast<const char*>(p) + k);
}

// Calls leaf(first, count) for every leaf of `bvh` (first block, triangle count) whose box meets
// [tnear, tfar] along `ray`, by the same conservative slab test as traverse_wide (Ize's widening,
// core/bbox.h), so no leaf that holds a crossing in the segment is missed. A true return from
// leaf ends the walk (an answer already decided).
template <class LeafFn>
inline void walk_all_leaves(const WideBvh& bvh, const TriangleBlock* blocks, const RayBoxData& ray, float tnear,
                            float tfar, LeafFn&& leaf) {
  using namespace simd;
  if (bvh.nodes.empty()) {
    if (bvh.root_leaf_count) (void)leaf(bvh.root_leaf_first, bvh.root_leaf_count);
    return;
  }
  const vfloat ox = splat(ray.org.x), oy = splat(ray.org.y), oz = splat(ray.org.z);
  const vfloat ix = splat(ray.inv_dir.x), iy = splat(ray.inv_dir.y), iz = splat(ray.inv_dir.z);
  const vfloat start = splat(tnear), end = splat(tfar);
  const vfloat widen = splat(1.0f + 2.0f * gamma(3)), shrink = splat(1.0f - 2.0f * gamma(3));
  const bool negative_start = tnear < 0.0f;

  struct Entry {
    uint32_t child, count;
  };
  Entry stack[(kWidth - 1) * kMaxBvhDepth + 1];
  int sp = 0;
  Entry current{0, 0};
  for (;;) {
    if (current.count == 0) {
      const WideNode& n = bvh.nodes[current.child];
      const vfloat tnx = (load(n.bounds[ray.near[0]]) - ox) * ix, tfx = (load(n.bounds[ray.far[0]]) - ox) * ix;
      const vfloat tny = (load(n.bounds[ray.near[1]]) - oy) * iy, tfy = (load(n.bounds[ray.far[1]]) - oy) * iy;
      const vfloat tnz = (load(n.bounds[ray.near[2]]) - oz) * iz, tfz = (load(n.bounds[ray.far[2]]) - oz) * iz;
      vfloat tmin = max_keep(max_keep(max_keep(start, tnx), tny), tnz);
      vfloat tmax = min_keep(min_keep(min_keep(splat(kInfinity), tfx), tfy), tfz);
      if (negative_start) {
        tmin = tmin < 0.0f ? tmin * widen : tmin;
        tmax = tmax * (tmax < 0.0f ? shrink : widen);
      } else {
        tmax = tmax * widen;
      }
      tmax = min_keep(tmax, end);
      uint32_t mask = mask_of(tmin <= tmax);
      while (mask) {
        const int i = __builtin_ctz(mask);
        mask &= mask - 1;
        const Entry e{n.child[i], n.count[i]};
        if (e.count == 0)
          prefetch_lines(&bvh.nodes[e.child], sizeof(WideNode));
        else
          prefetch_lines(&blocks[e.child], sizeof(TriangleBlock));
        stack[sp++] = e;
      }
    } else if (leaf(current.child, current.count)) {
      return;
    }
    if (sp == 0) return;
    current = stack[--sp];
  }
}

}  // namespace toyrt::queries
