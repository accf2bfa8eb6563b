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

template <bool AnyHit, class LeafFn>
[[gnu::always_inline]] inline bool traverse_wide(const WideBvh& bvh, const RayBoxData& ray, float tnear, float& tfar,
                                                 LeafFn&& leaf) {
  using namespace simd;
  if (bvh.nodes.empty()) return bvh.root_leaf_count && leaf(bvh.root_leaf_first, bvh.root_leaf_count, tfar);

  const vfloat ox = splat(ray.org.x), oy = splat(ray.org.y), oz = splat(ray.org.z);
  const vfloat ix = splat(ray.inv_dir.x), iy = splat(ray.inv_dir.y), iz = splat(ray.inv_dir.z);
  const vfloat start = splat(tnear);
  // Conservative distances, as in intersect_box: exits moved out, negative entries moved back.
  const vfloat widen = splat(1.0f + 2.0f * gamma(3)), shrink = splat(1.0f - 2.0f * gamma(3));
  const bool negative_start = tnear < 0.0f;
  // Byte offsets of the near and far rows in a node (for load_at).
  constexpr size_t kRow = sizeof(float) * kWidth;
  const size_t near_x = size_t(ray.near[0]) * kRow, near_y = size_t(ray.near[1]) * kRow,
               near_z = size_t(ray.near[2]) * kRow;
  const size_t far_x = size_t(ray.far[0]) * kRow, far_y = size_t(ray.far[1]) * kRow, far_z = size_t(ray.far[2]) * kRow;

  struct Entry {
    uint32_t child, count;
    float tentry;
  };
  Entry stack[(kWidth - 1) * kMaxBvhDepth + 1];
  int sp = 0;
  Entry current{0, 0, tnear};
  bool found = false;
  for (;;) {
    if (current.count == 0) {
      const WideNode& n = bvh.nodes[current.child];
      const vfloat tnx = (load_at(n.bounds, near_x) - ox) * ix, tfx = (load_at(n.bounds, far_x) - ox) * ix;
      const vfloat tny = (load_at(n.bounds, near_y) - oy) * iy, tfy = (load_at(n.bounds, far_y) - oy) * iy;
      const vfloat tnz = (load_at(n.bounds, near_z) - oz) * iz, tfz = (load_at(n.bounds, far_z) - oz) * iz;
      // tfar joins the exits before the widening: a box entered just beyond tfar (within the
      // widening) is visited for nothing, rarely, and one broadcast and one min a visit are saved.
      vfloat tmin = max_keep(max_keep(max_keep(start, tnx), tny), tnz);
      vfloat tmax = min_keep(min_keep(min_keep(splat(tfar), tfx), tfy), tfz);
      if (negative_start) {  // rare (rays reaching back before their origin): the general form
        tmin = tmin < 0.0f ? tmin * widen : tmin;
        tmax = tmax * (tmax < 0.0f ? shrink : widen);
      } else {  // tmin >= 0, so a negative exit is a miss however it is scaled: Ize's form
        tmax = tmax * widen;
      }
      uint32_t mask = mask_of(tmin <= tmax);
      if (mask != 0 && AnyHit) {
        // Any hit ends the walk: no distance sort, the children hit in slot order, which
        // collapse() makes decreasing box area (the likeliest blockers first): the first now,
        // the rest stacked so that the next largest pops next. Entry tnear, never popped as
        // "beyond tfar" (an entry of 0 was, for segments ending before 0: occluded() missed what
        // intersect() found; found by tests/fuzz).
        const int first = __builtin_ctz(mask);
        current = Entry{n.child[first], n.count[first], tnear};
        for (mask &= mask - 1; mask; mask &= ~(1u << (31 - __builtin_clz(mask)))) {
          const int i = 31 - __builtin_clz(mask);
          stack[sp++] = Entry{n.child[i], n.count[i], tnear};
          if (n.count[i] == 0) __builtin_prefetch(&bvh.nodes[n.child[i]]);
        }
        continue;
      }
      if (mask != 0) {
        // One or two children hit is the common case: no sort, no array.
        const int first = __builtin_ctz(mask);
        const uint32_t rest = mask & (mask - 1);
        if (rest == 0) {
          current = Entry{n.child[first], n.count[first], tmin[first]};
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
          if (n.count[far] == 0) __builtin_prefetch(&bvh.nodes[n.child[far]]);
          current = Entry{n.child[near], n.count[near], tmin[near]};
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
          if (n.count[i] == 0) __builtin_prefetch(&bvh.nodes[n.child[i]]);
        }
        const int i = int(keys[0] & (kWidth - 1));
        current = Entry{n.child[i], n.count[i], tmin[i]};
        continue;
      }
    } else if (leaf(current.child, current.count, tfar)) {
      found = true;
      if constexpr (AnyHit) return true;
    }
    // Pop the next subtree that may still hold a nearer hit.
    for (;;) {
      if (sp == 0) return found;
      current = stack[--sp];
      if (current.tentry <= tfar) break;
    }
  }
}

}  // namespace toyrt
