// Traversal of a WideBvh: all kWidth child boxes of a node are slab-tested at once with SIMD
// vectors (GCC vector extensions: AVX with -march on current x86, SSE pairs otherwise), the
// children hit are visited nearest first, the others stacked with their entry distance.
// Same leaf callback contract as traverse.h.
#pragma once

#include "accel/wide_bvh.h"

#if defined(__SSE__)
#include <immintrin.h>
#endif

#include <cstring>
#include <utility>

namespace toyrt {

namespace simd {
using vfloat = float __attribute__((vector_size(kWidth * sizeof(float))));
using vint = int32_t __attribute__((vector_size(kWidth * sizeof(float))));

// A vector read through a may_alias type (GCC's own idiom for its load intrinsics). A memcpy into
// a vector local compiled, for x86-64-v3, to a load, a store to the stack and a reload. GCC
// honours the typedef's 4-byte alignment; clang keeps the vector's 32, so every caller passes
// 32-byte aligned rows (nodes and blocks are laid out so).
using vfloat_in_memory = float __attribute__((vector_size(kWidth * sizeof(float)), aligned(4), may_alias));
inline vfloat load(const float* p) { return *reinterpret_cast<const vfloat_in_memory*>(p); }
// The vector `offset` bytes past `base`: with the offset kept in a register the load is one
// addressing mode, where a row index would need a shift at every load.
inline vfloat load_at(const void* base, size_t offset) {
  return load(reinterpret_cast<const float*>(static_cast<const char*>(base) + offset));
}
// A broadcast. (Written as `vfloat{} + x` it was an addition and then a broadcast: 0 + x is not x
// for x = -0, so the compiler must add.)
inline vfloat splat(float x) {
  static_assert(kWidth == 8);
  return vfloat{x, x, x, x, x, x, x, x};
}
// Lane-wise max / min that keep `acc` where `candidate` is NaN (see safe_max in core/math.h).
// x86's maxps / minps answer exactly this (the first operand where the comparison holds, the
// second otherwise, NaN included); written as the comparison, GCC emitted a compare and a blend
// for some of them.
inline vfloat max_keep(vfloat acc, vfloat candidate) {
#if defined(__AVX__)
  static_assert(kWidth == 8);
  return reinterpret_cast<vfloat>(_mm256_max_ps(reinterpret_cast<__m256>(candidate), reinterpret_cast<__m256>(acc)));
#else
  return candidate > acc ? candidate : acc;
#endif
}
inline vfloat min_keep(vfloat acc, vfloat candidate) {
#if defined(__AVX__)
  return reinterpret_cast<vfloat>(_mm256_min_ps(reinterpret_cast<__m256>(candidate), reinterpret_cast<__m256>(acc)));
#else
  return candidate < acc ? candidate : acc;
#endif
}
// One bit per lane whose comparison result is true (all bits set).
template <class V>
inline uint32_t mask_of(V lanes) {
  constexpr int n = int(sizeof(V) / sizeof(int32_t));
#if defined(__AVX__)
  if constexpr (n == 8) return uint32_t(_mm256_movemask_ps(reinterpret_cast<__m256>(lanes)));
#elif defined(__SSE__)
  if constexpr (n == 8) {  // two SSE halves
    __m128 half[2];
    std::memcpy(half, &lanes, sizeof half);
    return uint32_t(_mm_movemask_ps(half[0])) | uint32_t(_mm_movemask_ps(half[1])) << 4;
  }
#endif
#if defined(__SSE__)
  if constexpr (n == 4) return uint32_t(_mm_movemask_ps(reinterpret_cast<__m128>(lanes)));
#endif
  uint32_t m = 0;
  for (int i = 0; i < n; ++i) m |= uint32_t(lanes[i] != 0) << i;
  return m;
}
}  // namespace simd

// A ray's slab test against the kWidth child boxes of a wide node: its constants broadcast once a
// ray, shared by both walks.
struct WideSlabTest {
  simd::vfloat ox, oy, oz, ix, iy, iz, start;
  bool negative_start;
  // Byte offsets of the near and far rows in a node (for load_at).
  size_t near_x, near_y, near_z, far_x, far_y, far_z;

  WideSlabTest(const RayBoxData& ray, float tnear) {
    using simd::splat;
    constexpr size_t kRow = sizeof(float) * kWidth;
    ox = splat(ray.org.x), oy = splat(ray.org.y), oz = splat(ray.org.z);
    ix = splat(ray.inv_dir.x), iy = splat(ray.inv_dir.y), iz = splat(ray.inv_dir.z);
    start = splat(tnear);
    negative_start = tnear < 0.0f;
    near_x = size_t(ray.near[0]) * kRow, near_y = size_t(ray.near[1]) * kRow, near_z = size_t(ray.near[2]) * kRow;
    far_x = size_t(ray.far[0]) * kRow, far_y = size_t(ray.far[1]) * kRow, far_z = size_t(ray.far[2]) * kRow;
  }

  // The slots whose boxes the ray enters before `end` (tfar broadcast), one bit each; their
  // entry distances in `tmin`.
  [[gnu::always_inline]] uint32_t enter(const WideNode& n, simd::vfloat end, simd::vfloat& tmin) const {
    using namespace simd;
    // Conservative distances, as in intersect_box: exits moved out, negative entries moved back.
    const vfloat widen = splat(1.0f + 2.0f * gamma(3)), shrink = splat(1.0f - 2.0f * gamma(3));
    const vfloat tnx = (load_at(n.bounds, near_x) - ox) * ix, tfx = (load_at(n.bounds, far_x) - ox) * ix;
    const vfloat tny = (load_at(n.bounds, near_y) - oy) * iy, tfy = (load_at(n.bounds, far_y) - oy) * iy;
    const vfloat tnz = (load_at(n.bounds, near_z) - oz) * iz, tfz = (load_at(n.bounds, far_z) - oz) * iz;
    // tfar joins the exits before the widening: a box entered just beyond tfar (within the
    // widening) is visited for nothing, rarely, and one broadcast and one min a visit are saved.
    tmin = max_keep(max_keep(max_keep(start, tnx), tny), tnz);
    vfloat tmax = min_keep(min_keep(min_keep(end, tfx), tfy), tfz);
    // The hint: without it GCC laid the common form out of line, two taken jumps a visit (10K
    // camera rays 2-4 % faster with it, docs/trace-speed.md, thirty-seventh session).
    if (__builtin_expect(negative_start, 0)) {  // rare (rays reaching back before their origin): the general form
      tmin = tmin < 0.0f ? tmin * widen : tmin;
      tmax = tmax * (tmax < 0.0f ? shrink : widen);
    } else {  // tmin >= 0, so a negative exit is a miss however it is scaled: Ize's form
      tmax = tmax * widen;
    }
    return mask_of(tmin <= tmax);
  }
};

// Starts fetching slot i's child when it is a node: the walks are bound by memory latency, and a
// stacked node is read a few steps later.
[[gnu::always_inline]] inline void prefetch_child(const WideBvh& bvh, const WideNode& n, int i) {
  if (n.count[i] == 0) __builtin_prefetch(&bvh.nodes[n.child[i]]);
}

// The closest-hit walk's caller may also start fetching a leaf's primitives as soon as the leaf
// is entered or stacked (prefetch_leaf(first, count)): a mesh's triangle blocks missed the cache
// on most leaves of a large mesh. Diffuse rays at 1M triangles on a first-generation EPYC: 5-6 %
// faster; 1 % when only the stacked leaves were fetched (all of a block's lines requested at
// once beat the block test's own loads). The any-hit walk, whose leaves' blocks fetched when
// stacked measured no gain, requests a leaf's block one step before testing it where the blocks
// are far beyond the caches (any_hit_wide<true>). Callers without one get this.
struct NoLeafPrefetch {
  void operator()(uint32_t, uint32_t) const {}
};
template <class PrefetchLeaf>
[[gnu::always_inline]] inline void prefetch_child(const WideBvh& bvh, const WideNode& n, int i,
                                                  PrefetchLeaf& prefetch_leaf) {
  if (n.count[i] == 0)
    __builtin_prefetch(&bvh.nodes[n.child[i]]);
  else
    prefetch_leaf(n.child[i], n.count[i]);
}

#if defined(__AVX2__)
// For each set of slots (a bit mask), the slots from the highest to the lowest, three bits each
// (the rest of the word: slot 0, filler): the order in which the any-hit walk stacks them, so that
// the lowest slot (the largest box) pops first.
struct DescendingSlots {
  uint32_t packed[1 << kWidth];
  constexpr DescendingSlots() : packed{} {
    for (uint32_t m = 0; m < (1u << kWidth); ++m) {
      uint32_t word = 0, k = 0;
      for (int slot = kWidth - 1; slot >= 0; --slot)
        if (m >> slot & 1) word |= uint32_t(slot) << (3 * k++);
      packed[m] = word;
    }
  }
};
inline constexpr DescendingSlots kDescendingSlots{};
#endif

// The any-hit walk: children entered in slot order, which collapse() makes decreasing box area
// (the likeliest blockers first), no distances kept (any hit ends the walk, so nothing is pruned
// by distance). Stacks of child and count side by side, so that a node's other children are
// stacked by two vector stores. With kOverlapLeaves, a leaf in flight (below).
template <bool kOverlapLeaves = false, class LeafFn, class PrefetchLeaf = NoLeafPrefetch>
[[gnu::always_inline]] inline bool any_hit_wide(const WideBvh& bvh, const RayBoxData& ray, float tnear, float tfar,
                                                LeafFn&& leaf, PrefetchLeaf&& prefetch_leaf = {}) {
  using namespace simd;
  if (bvh.nodes.empty()) return bvh.root_leaf_count && leaf(bvh.root_leaf_first, bvh.root_leaf_count, tfar);

  const WideSlabTest slab(ray, tnear);
  const vfloat end = splat(tfar);  // an any-hit walk never shortens its segment

  // kWidth - 1 a level at most, and room for a whole vector store at the top; one more for a
  // chosen child waiting while the leaf in flight is tested (kOverlapLeaves).
  constexpr int kStack = (kWidth - 1) * kMaxBvhDepth + kWidth + int(kOverlapLeaves);
  uint32_t stack_child[kStack], stack_count[kStack];
  int sp = 0;
  // Stacks the slots `slots` of node `n`, highest first.
  auto push = [&](const WideNode& n, uint32_t slots) __attribute__((always_inline)) {
#if defined(__AVX2__)
    const __m256i order = _mm256_and_si256(_mm256_srlv_epi32(_mm256_set1_epi32(int(kDescendingSlots.packed[slots])),
                                                             _mm256_setr_epi32(0, 3, 6, 9, 12, 15, 18, 21)),
                                           _mm256_set1_epi32(7));
    const __m256i counts = _mm256_load_si256(reinterpret_cast<const __m256i*>(n.count));
    _mm256_storeu_si256(
        reinterpret_cast<__m256i*>(stack_child + sp),
        _mm256_permutevar8x32_epi32(_mm256_load_si256(reinterpret_cast<const __m256i*>(n.child)), order));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(stack_count + sp), _mm256_permutevar8x32_epi32(counts, order));
    sp += __builtin_popcount(slots);
    // Start fetching the stacked subtrees now: traversal is bound by memory latency.
    const uint32_t interior =
        slots & uint32_t(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(counts, _mm256_setzero_si256()))));
    for (uint32_t m = interior; m; m &= m - 1) __builtin_prefetch(&bvh.nodes[n.child[__builtin_ctz(m)]]);
#else
    for (uint32_t m = slots; m; m &= ~(1u << (31 - __builtin_clz(m)))) {
      const int i = 31 - __builtin_clz(m);
      stack_child[sp] = n.child[i];
      stack_count[sp++] = n.count[i];
      prefetch_child(bvh, n, i);
    }
#endif
  };
  uint32_t child = 0, count = 0;  // the root
  // A leaf first among a node's children is tested before the others are stacked: when it
  // blocks (a wall beside a dense model) the stacking would be wasted.
  const WideNode* deferred_node = nullptr;
  uint32_t deferred = 0;
  if constexpr (kOverlapLeaves) {
    // kOverlapLeaves: one leaf in flight. A leaf reached is requested and tested one step later,
    // after the next node visit or once the next leaf has been requested, so that its block's lines
    // arrive meanwhile. But a leaf that one of a ray's first two visits enters first is tested at
    // once, as in the plain walk: the top of the tree is reached by most rays and stays cached, and
    // its leaves are the likeliest blockers (a room's walls: put in flight, 29 % of the closed room's
    // shadow rays visited a node of the model before the wall that blocked them). One call of `leaf`
    // in the loop, reached by jumps: with four, the block test inlined at each, the walk's code doubled.
    uint32_t pending_child = 0, pending_count = 0;
    bool at_once = false;
    int visits = 0;
    for (;;) {
      if (count == 0) {
        const bool near_top = ++visits <= 2;
        const WideNode& n = bvh.nodes[child];
        vfloat tmin;
        const uint32_t mask = slab.enter(n, end, tmin);
        if (mask == 0) {
          if (pending_count != 0) goto test_pending;
          goto pop;
        }
        const int first = __builtin_ctz(mask);
        const uint32_t rest = mask & (mask - 1);
        child = n.child[first];
        count = n.count[first];
        if (count != 0 && near_top) {
          deferred_node = &n;
          deferred = rest;
          at_once = true;
        } else if (rest != 0) {
          push(n, rest);
        }
        if (pending_count != 0) {
          // The chosen child waits on the stack while the leaf in flight is tested.
          stack_child[sp] = child;
          stack_count[sp++] = count;
          goto test_pending;
        }
        continue;
      }
      if (!at_once) {
        prefetch_leaf(child, count);
        std::swap(child, pending_child);
        std::swap(count, pending_count);
        if (count == 0) goto pop;  // nothing was in flight
      }
    test:
      if (leaf(child, count, tfar)) return true;
      at_once = false;
      if (deferred != 0) {
        push(*deferred_node, deferred);
        deferred = 0;
      }
    pop:
      if (sp == 0) {
        if (pending_count != 0) goto test_pending;
        return false;
      }
      --sp;
      child = stack_child[sp];
      count = stack_count[sp];
      continue;
    test_pending:
      child = pending_child;
      count = pending_count;
      pending_count = 0;
      goto test;
    }
  } else {
    for (;;) {
      if (count == 0) {
        const WideNode& n = bvh.nodes[child];
        vfloat tmin;
        const uint32_t mask = slab.enter(n, end, tmin);
        if (mask != 0) {
          const int first = __builtin_ctz(mask);
          const uint32_t rest = mask & (mask - 1);
          child = n.child[first];
          count = n.count[first];
          if (count != 0) {
            deferred_node = &n;
            deferred = rest;
          } else if (rest != 0) {
            push(n, rest);
          }
          continue;
        }
      } else {
        if (leaf(child, count, tfar)) return true;
        if (deferred != 0) {
          push(*deferred_node, deferred);
          deferred = 0;
        }
      }
      if (sp == 0) return false;
      --sp;
      child = stack_child[sp];
      count = stack_count[sp];
    }
  }
}

// The slots `mask` sorted by their entry distance in `tmin`, nearest first, ties in slot order (a
// stable sort), into keys (slot in the low bits); returns their number. 64-bit keys, the
// distance's bits made orderable as integers above the slot, sorted by compare-exchanges that
// compile to conditional moves (branches here were mispredicted as often as not). +0 first turns
// a -0 into 0, which the float comparison calls equal.
[[gnu::always_inline]] inline int sort_by_entry(uint32_t mask, const simd::vfloat& tmin, uint64_t keys[kWidth]) {
  using namespace simd;
  const vint bits = reinterpret_cast<vint>(tmin + 0.0f);
  const vint ordered = bits ^ ((bits >> 31) | int32_t(0x80000000u));  // negatives: all bits flipped
  int count = 0;
  for (; mask; mask &= mask - 1) {
    const int i = __builtin_ctz(mask);
    keys[count++] = uint64_t(uint32_t(ordered[i])) << 32 | uint32_t(i);
  }
  for (int i = 1; i < count; ++i)
    for (int j = i; j > 0; --j) {
      const uint64_t a = keys[j - 1], b = keys[j];
      keys[j - 1] = a < b ? a : b;
      keys[j] = a < b ? b : a;
    }
  return count;
}

// The closest-hit walk: the children entered visited nearest first, the others stacked with
// their entry distance and skipped when they pop beyond the nearest hit found by then.
// With kOverlapLeaves (a mesh whose leaves are beyond the caches, and fetched ahead by
// prefetch_leaf), a leaf that a node visit has just made the nearest is tested only after the
// interior node on top of the stack has been visited, so that the leaf's lines arrive meanwhile:
// that node's children are stacked, nearest on top, and each skipped at its pop if the leaf holds
// a nearer hit, as every stacked entry is. The leaves are tested in the same order either way
// (but for a child entered within rounding beyond the leaf's hit, which the plain walk's widened
// slab test would still visit and the pop skips). In one process, both forms alternating: 1M
// triangles primary rays 2.4-3.0 % faster, diffuse 2.3-3.3 %; 4M 4.4-5.3 % and 3.0-3.9 %; at
// 10K, where the blocks are in cache, nothing to wait for (docs/trace-speed.md, thirty-fifth
// session).
template <bool kOverlapLeaves = false, class LeafFn, class PrefetchLeaf = NoLeafPrefetch>
[[gnu::always_inline]] inline bool closest_hit_wide(const WideBvh& bvh, const RayBoxData& ray, float tnear, float& tfar,
                                                    LeafFn&& leaf, PrefetchLeaf&& prefetch_leaf = {}) {
  using namespace simd;
  if (bvh.nodes.empty()) return bvh.root_leaf_count && leaf(bvh.root_leaf_first, bvh.root_leaf_count, tfar);
  const WideSlabTest slab(ray, tnear);

  struct Entry {
    uint32_t child, count;
    float tentry;
  };
  // kWidth - 1 a level; one more while an overlapped node's nearest child is stacked too.
  Entry stack[(kWidth - 1) * kMaxBvhDepth + 1 + int(kOverlapLeaves)];
  int sp = 0;
  Entry current{0, 0, tnear};
  bool found = false;
  bool fresh_leaf = false;  // current is a leaf the last node visit chose (kOverlapLeaves only)
  // (kOverlapLeaves) Stacks the slots `mask` of node n, all of them, farthest first, so the
  // nearest pops first: sorted as the three-or-more case below sorts them (written out there: the
  // plain walk calling sort_by_entry measured 2-3 % slower at 10K triangles).
  auto stack_all = [&](const WideNode& n, uint32_t mask, const vfloat& tmin) __attribute__((always_inline)) {
    uint64_t keys[kWidth];
    for (int k = sort_by_entry(mask, tmin, keys) - 1; k >= 0; --k) {
      const int i = int(keys[k] & (kWidth - 1));
      stack[sp++] = Entry{n.child[i], n.count[i], tmin[i]};
      prefetch_child(bvh, n, i, prefetch_leaf);
    }
  };
  for (;;) {
    if (current.count == 0) {
      const WideNode& n = bvh.nodes[current.child];
      // The node's last line (child and count) is read only once the slab test has chosen a
      // slot: requested now, its miss overlaps the three bounds lines' instead of following them.
      // In a mesh beyond the caches that is a wait fewer in each visit's chain (bench_trace, alternating
      // builds: 1M diffuse rays 0.915 -> 0.950 of Embree, 4M 0.96 -> 1.01, primary +1-4 %); in
      // cache it costs nothing measurable. The any-hit walk measured no change either way.
      __builtin_prefetch(n.child);
      vfloat tmin;
      uint32_t mask = slab.enter(n, splat(tfar), tmin);
      // Most visits enter a child (79 % of them over the 10K sphere's and the soup's rays, by a
      // profiled build's counts); the hint keeps that path in line (the soup's rays 2-6 % faster).
      if (__builtin_expect(mask != 0, 1)) {
        // One or two children hit is the common case: no sort, no array.
        const int first = __builtin_ctz(mask);
        const uint32_t rest = mask & (mask - 1);
        if (rest == 0) {
          current = Entry{n.child[first], n.count[first], tmin[first]};
          if (current.count != 0) prefetch_leaf(current.child, current.count);
          fresh_leaf = kOverlapLeaves && current.count != 0;
          continue;
        }
        if ((rest & (rest - 1)) == 0) {
          const int second = __builtin_ctz(rest);
          // The nearer by index, then one entry each: GCC still compiles the choice to a branch
          // (about 0.5 mispredictions a primary ray remain here; an integer-mask form without it
          // measured no faster). Ties keep slot order, as the sort below.
          const bool swapped = tmin[second] < tmin[first];
          const int near = swapped ? second : first, far = swapped ? first : second;
          stack[sp++] = Entry{n.child[far], n.count[far], tmin[far]};
          prefetch_child(bvh, n, far, prefetch_leaf);
          current = Entry{n.child[near], n.count[near], tmin[near]};
          if (current.count != 0) prefetch_leaf(current.child, current.count);
          fresh_leaf = kOverlapLeaves && current.count != 0;
          continue;
        }
        // Three or more: sorted by entry distance, ties in slot order (a stable sort), as
        // 64-bit keys, the distance's bits made orderable as integers above the slot, by
        // compare-exchanges that compile to conditional moves (branches here were mispredicted
        // as often as not). +0 first turns a -0 into 0, which the float comparison calls equal.
        const vint bits = reinterpret_cast<vint>(tmin + 0.0f);
        const vint ordered = bits ^ ((bits >> 31) | int32_t(0x80000000u));  // negatives: all bits flipped
        uint64_t keys[kWidth];
        int count = 0;
        for (; mask; mask &= mask - 1) {
          const int i = __builtin_ctz(mask);
          keys[count++] = uint64_t(uint32_t(ordered[i])) << 32 | uint32_t(i);
        }
        for (int i = 1; i < count; ++i)
          for (int j = i; j > 0; --j) {
            const uint64_t a = keys[j - 1], b = keys[j];
            keys[j - 1] = a < b ? a : b;
            keys[j] = a < b ? b : a;
          }
        for (int k = count - 1; k > 0; --k) {
          const int i = int(keys[k] & (kWidth - 1));
          stack[sp++] = Entry{n.child[i], n.count[i], tmin[i]};
          // Start fetching the stacked subtrees now: traversal is bound by memory latency.
          prefetch_child(bvh, n, i, prefetch_leaf);
        }
        const int i = int(keys[0] & (kWidth - 1));
        current = Entry{n.child[i], n.count[i], tmin[i]};
        if (current.count != 0) prefetch_leaf(current.child, current.count);
        fresh_leaf = kOverlapLeaves && current.count != 0;
        continue;
      }
    } else {
      if (kOverlapLeaves && fresh_leaf) {
        fresh_leaf = false;
        if (sp > 0 && stack[sp - 1].count == 0 && stack[sp - 1].tentry <= tfar) {
          const WideNode& n = bvh.nodes[stack[--sp].child];
          vfloat tmin;
          const uint32_t mask = slab.enter(n, splat(tfar), tmin);
          if (mask) stack_all(n, mask, tmin);
        }
      }
      if (leaf(current.child, current.count, tfar)) found = true;
    }
    // Pop the next subtree that may still hold a nearer hit.
    for (;;) {
      if (sp == 0) return found;
      current = stack[--sp];
      if (current.tentry <= tfar) break;
    }
  }
}

// Both walks behind one name: AnyHit stops at the first hit (occlusion), else the nearest
// (kOverlapLeaves: a leaf's block requested ahead of its test, in each walk its own way: see
// closest_hit_wide and any_hit_wide).
template <bool AnyHit, bool kOverlapLeaves = false, class LeafFn, class PrefetchLeaf = NoLeafPrefetch>
[[gnu::always_inline]] inline bool traverse_wide(const WideBvh& bvh, const RayBoxData& ray, float tnear, float& tfar,
                                                 LeafFn&& leaf, PrefetchLeaf&& prefetch_leaf = {}) {
  if constexpr (AnyHit)
    return any_hit_wide<kOverlapLeaves>(bvh, ray, tnear, tfar, leaf, prefetch_leaf);
  else
    return closest_hit_wide<kOverlapLeaves>(bvh, ray, tnear, tfar, leaf, prefetch_leaf);
}

}  // namespace toyrt
