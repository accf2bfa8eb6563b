// Leaf storage for tracing: triangles in blocks of eight, coordinates side by side, so the
// watertight test of triangle.h runs on a whole block with one set of SIMD instructions. Each lane
// evaluates exactly the scalar test's expressions (the build disables FMA contraction), so the
// block test is as watertight as the scalar one; the rare lanes that need the scalar test's
// double-precision paths are handed to it.
#pragma once

#include "accel/wide_traverse.h"
#include "core/ray.h"
#include "geometry/triangle.h"

#include <cstring>

namespace toyrt {

// Eight lanes: one AVX register per coordinate row, so a leaf of five to eight triangles (the
// SAH builder's leaves hold up to eight) costs one block test instead of two blocks of four;
// where AVX is absent (x86-64-v2) each row is two SSE registers.
inline constexpr int kBlockWidth = 8;
inline constexpr uint32_t kNoTriangle = 0xFFFFFFFFu;

struct alignas(32) TriangleBlock {
  float p[3][3][kBlockWidth];  // [vertex][axis][lane]
  uint32_t prim[kBlockWidth];  // triangle index in the mesh; kNoTriangle for an unused lane

  Vec3 vertex(int lane, int k) const { return {p[k][0][lane], p[k][1][lane], p[k][2][lane]}; }
};
static_assert(sizeof(TriangleBlock) == 320, "TriangleBlock: 9 coordinate rows and the ids");

namespace simdb {  // vectors of one lane per triangle of a block
using vfloat = float __attribute__((vector_size(kBlockWidth * sizeof(float))));
using vint = int32_t __attribute__((vector_size(kBlockWidth * sizeof(float))));
using simd::load;
using simd::load_at;
using simd::splat;
// A cast between vector types of one size reinterprets the bits (GCC's vector extension), in
// registers; through memcpy GCC went by the stack for some of these.
inline vint bits_of(vfloat x) { return reinterpret_cast<vint>(x); }
inline vfloat abs(vfloat x) { return reinterpret_cast<vfloat>(bits_of(x) & 0x7FFFFFFF); }
inline vfloat max(vfloat a, vfloat b) { return a > b ? a : b; }
inline vfloat min(vfloat a, vfloat b) { return a < b ? a : b; }
using vint_in_memory = int32_t __attribute__((vector_size(kBlockWidth * sizeof(int32_t)), aligned(4), may_alias));
using simd::mask_of;
}  // namespace simdb

// The ray's constants of the block test, broadcast once per ray: the leaf test runs at every leaf
// a ray reaches, and rebuilding them there (an axis picked through a switch, then a broadcast)
// cost about as much as a third of a block test.
struct BlockRay {
  // The shear of make_watertight_ray: the origin along its kx, ky, kz, the rows' byte offsets
  // within a vertex's rows of a block (for simd::load_at).
  simdb::vfloat ox, oy, oz;
  simdb::vfloat sx, sy, sz;
  size_t x_row, y_row, z_row;
  // For a block test compiled for one dominant axis kz (intersect_block_along<kZ>): the shear
  // along the two axes after kz in cyclic order, (kz + 1) % 3 and (kz + 2) % 3, fixed for each kz,
  // so that every row is read at a constant offset, and the origin by world axis, in the
  // registers of the walk's slab test, which broadcasts the same three floats.
  simdb::vfloat o[3];
  simdb::vfloat cyclic_sx, cyclic_sy;
  int kz;
};

inline BlockRay make_block_ray(const WatertightRay& r) {
  using simdb::splat;
  const float* org = &r.org.x;
  // make_watertight_ray swaps kx and ky where the dominant component is negative (to keep the
  // winding of its U, V, W); the cyclic axes do not. With the two axes exchanged every sheared x
  // and y trade places, so each edge function and the determinant change sign exactly (the
  // products are the same, and a - b = -(b - a) in floating point), and the sign tests, the
  // distance T / det and the error bound, which read |det| and det's sign only, come out bit for
  // bit the same.
  const bool swapped = r.kx != (r.kz + 1) % 3;
  return {splat(org[r.kx]),
          splat(org[r.ky]),
          splat(org[r.kz]),
          splat(r.sx),
          splat(r.sy),
          splat(r.sz),
          size_t(r.kx) * sizeof(float) * kBlockWidth,
          size_t(r.ky) * sizeof(float) * kBlockWidth,
          size_t(r.kz) * sizeof(float) * kBlockWidth,
          {splat(r.org.x), splat(r.org.y), splat(r.org.z)},
          splat(swapped ? r.sy : r.sx),
          splat(swapped ? r.sx : r.sy),
          r.kz};
}

// The lanes the vector test leaves to the scalar one, one at a time: `near_start` lanes take the
// double-precision distance of a crossing too close to tnear for float, `scalar` lanes (an exact
// zero edge function) the whole scalar test. Writes each hit lane's distance to t and returns the
// lanes hit; with AnyHit it stops at the first. Out of line and given no callback: as a lambda
// calling the caller's `hit` (which GCC called out of line), the hot path built that callback's
// closure in memory at every block tested, rare lanes or not (ten moves a block).
template <bool AnyHit>
[[gnu::noinline, gnu::cold]] inline uint32_t rare_lanes(const WatertightRay& r, const TriangleBlock& b,
                                                        uint32_t near_start, uint32_t scalar, float tnear, float tfar,
                                                        float t[kBlockWidth]) {
  uint32_t hits = 0;
  float u, v;
  for (uint32_t m = near_start; m; m &= m - 1) {
    const int lane = __builtin_ctz(m);
    if (near_start_in_double(r, b.vertex(lane, 0), b.vertex(lane, 1), b.vertex(lane, 2), tnear, tfar, t[lane], u, v)) {
      hits |= 1u << lane;
      if constexpr (AnyHit) return hits;
    }
  }
  for (uint32_t m = scalar; m; m &= m - 1) {
    const int lane = __builtin_ctz(m);
    if (intersect_triangle(r, b.vertex(lane, 0), b.vertex(lane, 1), b.vertex(lane, 2), tnear, tfar, t[lane], u, v)) {
      hits |= 1u << lane;
      if constexpr (AnyHit) return hits;
    }
  }
  return hits;
}

// Tests the block's triangles against [tnear, tfar). For each lane hit, hit(lane, t) is called
// (nearest lanes are not sorted; the caller keeps the minimum); with AnyHit the first ends it.
// With kSkip, the triangle `skip` (the one the ray leaves) is never hit. Returns whether any lane
// was hit.
// kZ: the ray's dominant axis, or -1 for the form that reads it from br at run time.
template <int kZ, bool AnyHit, bool kSkip, class OnHit>
[[gnu::always_inline]] inline bool intersect_block_along(const WatertightRay& r, const BlockRay& br,
                                                         const TriangleBlock& b, float tnear, float tfar, int32_t skip,
                                                         OnHit&& hit) {
  using namespace simdb;
  const vfloat sx = kZ >= 0 ? br.cyclic_sx : br.sx, sy = kZ >= 0 ? br.cyclic_sy : br.sy, sz = br.sz;
  // Translated and sheared vertices, exactly as intersect_triangle computes them (with kZ, up to
  // the exchange of x and y that make_block_ray explains).
  vfloat x[3], y[3], vz[3];
  for (int k = 0; k < 3; ++k) {
    if constexpr (kZ >= 0) {
      constexpr int kX = (kZ + 1) % 3, kY = (kZ + 2) % 3;
      vz[k] = load(b.p[k][kZ]) - br.o[kZ];
      x[k] = (load(b.p[k][kX]) - br.o[kX]) - sx * vz[k];
      y[k] = (load(b.p[k][kY]) - br.o[kY]) - sy * vz[k];
    } else {
      vz[k] = load_at(b.p[k], br.z_row) - br.oz;
      x[k] = (load_at(b.p[k], br.x_row) - br.ox) - sx * vz[k];
      y[k] = (load_at(b.p[k], br.y_row) - br.oy) - sy * vz[k];
    }
  }
  const vfloat eu = x[2] * y[1] - y[2] * x[1];
  const vfloat ev = x[0] * y[2] - y[0] * x[2];
  const vfloat ew = x[1] * y[0] - y[1] * x[0];
  const vfloat zero = splat(0.0f);
  const vint used = *reinterpret_cast<const vint_in_memory*>(b.prim) != vint{} - 1;  // lanes holding a triangle
  const vint exact_zero = (eu == zero) | (ev == zero) | (ew == zero);
  // Edge functions of both signs: the ray passes outside. By sign bits (not all equal), which is
  // the comparison's answer on every lane without an exact zero; those lanes go to the scalar
  // test whatever `mixed` says.
  const vint su = bits_of(eu), sv = bits_of(ev), sw = bits_of(ew);
  const vint mixed = ((su ^ sv) | (su ^ sw)) < vint{};
  // Most blocks a ray reaches it misses on every lane: stop before the depth and distance.
  if (!mask_of(used & (~mixed | exact_zero))) return false;
  vfloat z[3];
  for (int k = 0; k < 3; ++k) z[k] = sz * vz[k];
  const vfloat det = eu + ev + ew;
  const vfloat scaled_t = eu * z[0] + ev * z[1] + ew * z[2];
  const vfloat abs_det = abs(det);
  const vfloat signed_t = det < zero ? -scaled_t : scaled_t;
  const vint in_range = (det != zero) & (signed_t < splat(tfar) * abs_det);
  const vint candidate = used & ~mixed & in_range;
  uint32_t live = mask_of(candidate | (used & exact_zero));
  // The triangle the ray leaves is dropped here, where a block still has a candidate, and before
  // the error bound, which it would otherwise reach only to be rejected (Ray::self).
  if constexpr (kSkip) live &= ~mask_of(*reinterpret_cast<const vint_in_memory*>(b.prim) == skip);
  // Or misses by distance: stop before the error bound.
  if (!live) return false;

  // start_side of triangle.h, lane-wise: lanes wholly ahead of the origin's plane across the
  // dominant axis are past the start, lanes wholly behind it before the start, without the bound.
  const vint decided = candidate & ~exact_zero;  // lanes the vector test decides
  const vfloat z_low = min(min(z[0], z[1]), z[2]), z_high = max(max(z[0], z[1]), z[2]);
  const vint finite_det = abs_det <= splat(std::numeric_limits<float>::max());
  const vint ahead = (z_low > splat(tnear <= 0.0f ? 0.0f : kInfinity)) & finite_det;
  const vint behind = (z_high < splat(tnear >= 0.0f ? 0.0f : -kInfinity)) & finite_det;
  uint32_t accepted = mask_of(decided & ahead) & live;
  uint32_t near_start = 0;
  if (const uint32_t across = mask_of(decided & ~ahead & ~behind) & live) {
    // near_start_error of triangle.h, lane-wise.
    const vfloat max_z = max(max(abs(z[0]), abs(z[1])), abs(z[2]));
    const vfloat max_xy = max(max(max(abs(x[0]), abs(x[1])), abs(x[2])), max(max(abs(y[0]), abs(y[1])), abs(y[2])));
    const vfloat error = near_start_error(max_xy, max_z, abs_det, tnear);
    const vfloat past_start = signed_t - splat(tnear) * abs_det;
    const uint32_t clear_of_start = mask_of(past_start > error);
    // As far before the start as clear_of_start is after it (the same bound, so as sure): a miss
    // in float. These are mostly the surface a ray leaves and its neighbours, which would
    // otherwise all be sent to the double-precision distance only to be rejected there.
    const uint32_t clear_before_start = mask_of(past_start < -error);
    accepted |= across & clear_of_start;
    // Lanes inside the triangle whose distance is too close to tnear for float (mostly the
    // surface a ray leaves): their crossing is decided in double directly, as the scalar test
    // would after repeating the same float arithmetic.
    near_start = across & ~clear_of_start & ~clear_before_start;
  }
  // Lanes with an exact zero edge function take the whole scalar test.
  const uint32_t scalar = mask_of(used & exact_zero) & live;
  bool any = false;
  if (accepted) {
    const vfloat t = scaled_t * (splat(1.0f) / det);  // as the scalar test: times the reciprocal
    for (uint32_t m = accepted; m; m &= m - 1) {
      const int lane = __builtin_ctz(m);
      hit(lane, t[lane]);
      any = true;
      if constexpr (AnyHit) return true;
    }
  }
  if (__builtin_expect((near_start | scalar) != 0, 0)) {
    float rare_t[kBlockWidth];
    const uint32_t rare_hits = rare_lanes<AnyHit>(r, b, near_start, scalar, tnear, tfar, rare_t);
    // The near-start lanes first, then the scalar ones: the order in which they were tested.
    for (const uint32_t lanes : {rare_hits & near_start, rare_hits & scalar})
      for (uint32_t m = lanes; m; m &= m - 1) {
        const int lane = __builtin_ctz(m);
        hit(lane, rare_t[lane]);
        any = true;
        if constexpr (AnyHit) return true;
      }
  }
  return any;
}

// The block test. For occlusion, compiled for each dominant axis and chosen by a branch that all
// of a ray's blocks take the same way: the rows at constant offsets need no registers, and the
// origin is the slab test's own broadcasts, so the any-hit walk spills and reloads less around
// each leaf (stack accesses in its code 89 -> 64) and the shadow rows of the soup and the 1M
// sphere trace 2-3 % faster (docs/trace-speed.md, forty-second session). The closest-hit walk
// keeps the form with the rows' offsets in registers and make_watertight_ray's axes: built the
// same way, or with the cyclic axes alone, it traced the 1M sphere's diffuse rays 3.5 % slower.
template <bool AnyHit, bool kSkip, class OnHit>
[[gnu::always_inline]] inline bool intersect_block(const WatertightRay& r, const BlockRay& br, const TriangleBlock& b,
                                                   float tnear, float tfar, int32_t skip, OnHit&& hit) {
  if constexpr (!AnyHit) {
    return intersect_block_along<-1, AnyHit, kSkip>(r, br, b, tnear, tfar, skip, hit);
  } else {
    switch (br.kz) {
      case 0:
        return intersect_block_along<0, AnyHit, kSkip>(r, br, b, tnear, tfar, skip, hit);
      case 1:
        return intersect_block_along<1, AnyHit, kSkip>(r, br, b, tnear, tfar, skip, hit);
      default:
        return intersect_block_along<2, AnyHit, kSkip>(r, br, b, tnear, tfar, skip, hit);
    }
  }
}

}  // namespace toyrt
