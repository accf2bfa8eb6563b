// The exact crossing test over a leaf block of triangles (geometry/triangle_block.h): filters
// reject the lanes whose edge signs are certified to disagree (the ray certainly passes outside),
// and only the remaining lanes run the scalar exact test of queries/exact_crossing.h. A certified
// sign is the exact sign, so the filters change no answer. The first filter runs all eight lanes
// in float (one AVX register per row); where it cannot run (flush-to-zero arithmetic) the double
// filter does, four lanes at a time.
#pragma once

#include "geometry/triangle_block.h"
#include "queries/exact_crossing.h"

#if defined(__SSE__)
#include <immintrin.h>
#endif

#include <cstring>

namespace toyrt::queries {

// The float filter's view of a ray: origin and direction are floats (ExactRay holds them
// converted exactly), the direction's magnitudes, and the absolute error term below.
struct FloatFilterRay {
  float org[3], dir[3], abs_dir[3];
  float floor;
};

inline FloatFilterRay float_filter_ray(const ExactRay& r) {
  FloatFilterRay f;
  for (int a = 0; a < 3; ++a) {
    f.org[a] = float(r.org[a]);
    f.dir[a] = float(r.dir[a]);
    f.abs_dir[a] = std::fabs(f.dir[a]);
  }
  // What underflow can add: each product and each multiple of a direction component that lands
  // in float's subnormal range is off by at most 2^-150, and at most nine such errors, scaled by
  // |d|, reach the value and its bound; 2^-140 (1 + |d|_1) covers them a thousand times over.
  f.floor = 0x1p-140f * (1.0f + f.abs_dir[0] + f.abs_dir[1] + f.abs_dir[2]);
  return f;
}

// Whether float arithmetic keeps subnormals (IEEE, the default): the float filter's underflow
// term assumes it. Under flush-to-zero or denormals-are-zero (a caller's MXCSR) a translated
// coordinate can flush to 0, an error no term relative to the rounded values bounds.
inline bool float_filter_usable() {
#if defined(__SSE__)
  return (_mm_getcsr() & 0x8040u) == 0;  // FTZ (bit 15) and DAZ (bit 6) clear
#else
  return false;
#endif
}

// The error bound of the float filter, relative to sum |d_i| (|p| + |q|) of the computed
// products. The value of P(a, b) goes through seven roundings per product term (two
// translations, the product, the difference, the multiple of d, two sums: gamma(7) ~ 7u) and
// the computed magnitudes underestimate the exact ones by gamma(8) at most; the double model's
// own translation (queries/exact_crossing.h) differs from the exact one by 2^-53 relative.
// 16u = 2^-20 covers the lot with room.
inline constexpr float kFloatTripleErrorBound = 0x1p-20f;

// A mask of the used lanes of `b` the perturbed ray may cross: every other lane has two edges
// whose Plücker signs are certified, in float, to disagree. With `on_plane`, also the lanes whose
// plane may hold the ray's origin: the others have a volume det(A, B, C) certified nonzero (the
// same products as the edge (B, C), the same bound with A in place of the direction, and the
// underflow term per lane), so the origin lies on none of them (compute_occupancy's on-surface
// test runs on the rest).
[[gnu::always_inline]] inline uint32_t float_candidates(const FloatFilterRay& r, const TriangleBlock& b,
                                                        uint32_t* on_plane = nullptr) {
  using namespace simdb;
  vfloat x[3], y[3], z[3];
  for (int k = 0; k < 3; ++k) {
    x[k] = load(b.p[k][0]) - splat(r.org[0]);
    y[k] = load(b.p[k][1]) - splat(r.org[1]);
    z[k] = load(b.p[k][2]) - splat(r.org[2]);
  }
  const vfloat dx = splat(r.dir[0]), dy = splat(r.dir[1]), dz = splat(r.dir[2]);
  const vfloat adx = splat(r.abs_dir[0]), ady = splat(r.abs_dir[1]), adz = splat(r.abs_dir[2]);
  vint pos = vint{}, neg = vint{};
  for (int e = 0; e < 3; ++e) {
    const int i = e, j = (e + 1) % 3;  // the edges and products of edge_side, as below
    const vfloat p0 = y[i] * z[j], p1 = z[i] * y[j], p2 = z[i] * x[j], p3 = x[i] * z[j], p4 = x[i] * y[j],
                 p5 = y[i] * x[j];
    const vfloat value = dx * (p0 - p1) + dy * (p2 - p3) + dz * (p4 - p5);
    const vfloat bound = splat(kFloatTripleErrorBound) *
                             (adx * (abs(p0) + abs(p1)) + ady * (abs(p2) + abs(p3)) + adz * (abs(p4) + abs(p5))) +
                         splat(r.floor);
    pos |= value > bound;  // false for NaN (inf - inf on overflow): never certified
    neg |= value < -bound;
    if (e == 1 && on_plane) {
      const vfloat ax = abs(x[0]), ay = abs(y[0]), az = abs(z[0]);
      const vfloat volume = x[0] * (p0 - p1) + y[0] * (p2 - p3) + z[0] * (p4 - p5);
      const vfloat volume_bound = splat(kFloatTripleErrorBound) *
                                      (ax * (abs(p0) + abs(p1)) + ay * (abs(p2) + abs(p3)) + az * (abs(p4) + abs(p5))) +
                                  splat(0x1p-140f) * (splat(1.0f) + ax + ay + az);
      *on_plane = mask_of(~(abs(volume) > volume_bound));
    }
  }
  vint used;
  std::memcpy(&used, b.prim, sizeof used);
  used = used != vint{} - 1;
  if (on_plane) *on_plane &= mask_of(used);
  return mask_of(used & ~(pos & neg));
}

namespace simd4d {
using vdouble = double __attribute__((vector_size(4 * sizeof(double))));
using vlong = int64_t __attribute__((vector_size(4 * sizeof(double))));
inline vdouble load(const float* p) {
  float __attribute__((vector_size(4 * sizeof(float)))) f;
  std::memcpy(&f, p, sizeof f);
  return __builtin_convertvector(f, vdouble);
}
inline vdouble abs(vdouble x) { return x < 0.0 ? -x : x; }
}  // namespace simd4d

// Calls visit(crossing, prim) for each lane of `b` the perturbed ray crosses.
// Four lanes of `b` from `lane0`: four doubles are one AVX register.
template <class Visit>
inline void quad_crossings(const ExactRay& r, const TriangleBlock& b, int lane0, Visit&& visit) {
  using namespace simd4d;
  vdouble x[3], y[3], z[3];
  for (int k = 0; k < 3; ++k) {
    x[k] = load(b.p[k][0] + lane0) - r.org.x;
    y[k] = load(b.p[k][1] + lane0) - r.org.y;
    z[k] = load(b.p[k][2] + lane0) - r.org.z;
  }
  const double dx = r.dir.x, dy = r.dir.y, dz = r.dir.z;
  const double adx = std::fabs(dx), ady = std::fabs(dy), adz = std::fabs(dz);
  vlong pos = vlong{}, neg = vlong{};
  for (int e = 0; e < 3; ++e) {
    const int i = e, j = (e + 1) % 3;  // edges (0,1), (1,2), (2,0): the products of edge_side
    const vdouble p0 = y[i] * z[j], p1 = z[i] * y[j], p2 = z[i] * x[j], p3 = x[i] * z[j], p4 = x[i] * y[j],
                  p5 = y[i] * x[j];
    const vdouble value = dx * (p0 - p1) + dy * (p2 - p3) + dz * (p4 - p5);
    const vdouble bound =
        kTripleErrorBound * (adx * (abs(p0) + abs(p1)) + ady * (abs(p2) + abs(p3)) + adz * (abs(p4) + abs(p5)));
    pos |= value > bound;
    neg |= value < -bound;
  }
  for (int k = 0; k < 4; ++k) {
    const int lane = lane0 + k;
    if (b.prim[lane] == kNoTriangle || (pos[k] && neg[k])) continue;
    Crossing c;
    if (exact_crossing(r, b.vertex(lane, 0), b.vertex(lane, 1), b.vertex(lane, 2), c)) visit(c, b.prim[lane]);
  }
}

// Calls visit(crossing, prim) for each lane of `b` the perturbed ray crosses: the float filter,
// then the exact test on the lanes it leaves.
template <class Visit>
inline void block_crossings(const ExactRay& r, const FloatFilterRay& fr, const TriangleBlock& b, Visit&& visit) {
  for (uint32_t m = float_candidates(fr, b); m; m &= m - 1) {
    const int lane = __builtin_ctz(m);
    Crossing c;
    if (exact_crossing(r, b.vertex(lane, 0), b.vertex(lane, 1), b.vertex(lane, 2), c)) visit(c, b.prim[lane]);
  }
}

// Calls visit(crossing, prim) for each lane of `b` the perturbed ray crosses, with the double
// filter only (where the float one cannot run).
template <class Visit>
inline void block_crossings(const ExactRay& r, const TriangleBlock& b, Visit&& visit) {
  static_assert(kBlockWidth % 4 == 0, "blocks are filtered four lanes at a time");
  for (int lane0 = 0; lane0 < kBlockWidth; lane0 += 4) {
    if (b.prim[lane0] == kNoTriangle) break;  // lanes fill from 0: the rest are empty too
    quad_crossings(r, b, lane0, visit);
  }
}

}  // namespace toyrt::queries
