// The checks every light placed by its object's world matrix (area, spot, sun) needs before
// reading positions and axes from it, with one wording for their errors.
#pragma once

#include "core/math.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace toyrt {

// Throws std::invalid_argument ("<subject>: matrix_world is not finite", "... must be affine")
// unless m is finite and affine.
inline void check_light_matrix(const Mat4& m, const char* subject) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) throw std::invalid_argument(std::string(subject) + ": matrix_world is not finite");
  if (m[0][3] != 0.0f || m[1][3] != 0.0f || m[2][3] != 0.0f || m[3][3] != 1.0f)
    throw std::invalid_argument(std::string(subject) + ": matrix_world must be affine: its last row must be 0 0 0 1");
}

}  // namespace toyrt
