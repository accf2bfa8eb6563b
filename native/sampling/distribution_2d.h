// A piecewise-constant density on the unit square, over a width x height grid of non-negative
// weights: a cell is chosen with probability proportional to its weight (a row by the marginal
// CDF, then a column by that row's conditional CDF, both by binary search) and the point is
// uniform inside it, so the density at (u, v) is weight(cell) / mean weight. An all-zero grid
// is uniform. Used for importance-sampling environment maps (weight = luminance x sin(theta)).
#pragma once

#include "core/math.h"
#include "sampling/warp.h"

#include <cstdint>
#include <vector>

namespace toyrt {

struct Distribution2D {
  int width = 0, height = 0;
  std::vector<float> conditional;  // height rows of width + 1 CDF values, each 0 .. 1
  std::vector<float> marginal;     // height + 1 CDF values over the rows
  std::vector<float> density;      // width * height: each cell's density (weight / mean weight)

  // Throws std::invalid_argument for non-positive sizes, a size mismatch or a negative or
  // non-finite weight.
  static Distribution2D build(const std::vector<float>& weights, int width, int height);

  bool empty() const { return width == 0; }
  // A point for two uniform numbers, and its density (> 0).
  Vec2 sample(const Vec2& u, float& pdf) const;
  float pdf(const Vec2& uv) const;  // uv wrapped into the square's cells by clamping
};

}  // namespace toyrt
