// Morton codes of box centres, shared by the LBVH's reference build and its host build (the
// kernels in kernels/lbvh.cl repeat the same float operations): the centroid box is cut into
// 2^bits cells per axis, and a centre's cell coordinates are interleaved bit by bit, x highest.
#pragma once

#include "accel/lbvh_layout.h"
#include "core/bbox.h"

#include <cstdint>

namespace toyrt {

// The quantisation frame: cells per unit length on each axis (0 on a flat axis).
struct MortonFrame {
  Vec3 lo, scale;
  uint32_t bits;
};

inline MortonFrame morton_frame(const BBox& centroid_bounds, MortonBits bits) {
  const uint32_t b = uint32_t(bits);
  const float cells = float((1u << b) - 1u);
  const Vec3 extent = centroid_bounds.extent();
  MortonFrame f{centroid_bounds.lo, Vec3(0.0f), b};
  for (int a = 0; a < 3; ++a) f.scale[a] = extent[a] > 0.0f ? cells / extent[a] : 0.0f;
  return f;
}

// A centre's cell on axis a: clamped to [0, cells] as the kernel's fmin(fmax(q, 0), cells), which
// drops the NaN of 0 * inf (a denormal extent gives an infinite scale) that would otherwise reach
// an undefined cast (found by tests/fuzz). Written as comparisons, which a NaN fails: std::fmax
// and std::fmin compile to library calls here, two a coordinate.
inline uint32_t morton_cell(const Vec3& c, const MortonFrame& f, int a) {
  const float cells = float((1u << f.bits) - 1u);
  const float q = (c[a] - f.lo[a]) * f.scale[a];
  const float at_least_0 = q > 0.0f ? q : 0.0f;
  return uint32_t(at_least_0 < cells ? at_least_0 : cells);
}

}  // namespace toyrt
