// The exact crossing test over a leaf block of triangles (geometry/triangle_block.h): a
// filter in double-precision SIMD rejects the lanes whose edge signs are certified to disagree (the
// ray certainly passes outside), and only the remaining lanes run the scalar exact test of
// queries/exact_crossing.h. A certified sign is the exact sign, so the filter changes no answer.
#pragma once

#include "geometry/triangle_block.h"
#include "queries/exact_crossing.h"

#include <cstring>

namespace toyrt::queries {

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

// Calls visit(crossing, prim) for each lane of `b` the perturbed ray crosses.
template <class Visit>
inline void block_crossings(const ExactRay& r, const TriangleBlock& b, Visit&& visit) {
  static_assert(kBlockWidth % 4 == 0, "blocks are filtered four lanes at a time");
  for (int lane0 = 0; lane0 < kBlockWidth; lane0 += 4) {
    if (b.prim[lane0] == kNoTriangle) break;  // lanes fill from 0: the rest are empty too
    quad_crossings(r, b, lane0, visit);
  }
}

}  // namespace toyrt::queries
