// Renders of one image in passes (samples [0, n1), then [n1, n1 + n2), ...: the time limit), added
// up into one render as if its samples had been taken in one go. Per pixel, with n_a samples
// accumulated and n_p in the new pass (they differ between pixels under adaptive sampling):
//   Combined and the averaged passes (mist, normal, diffuse colour, emission): the weighted mean;
//   depth, position and the indices: the first pass's (Cycles takes them from sample 0);
//   Cryptomatte: each id's coverage as the weighted mean, ranked again. Only the `depth` ids a pass
//     kept can be merged: an id below every pass's top `depth` is lost, where one render keeps it.
#pragma once

#include "render/renderer.h"

#include <cstdint>
#include <vector>

namespace toyrt {

// Adds `pass` into `into` over `tile`; counts_into / counts_pass: samples per window pixel
// (row-major, result width). counts_into grows by counts_pass there.
void accumulate_tile(RenderResult& into, std::vector<uint32_t>& counts_into, const RenderResult& pass,
                     const std::vector<uint32_t>& counts_pass, const Tile& tile, int cryptomatte_depth);

}  // namespace toyrt
