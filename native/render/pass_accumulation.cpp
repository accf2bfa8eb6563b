#include "render/pass_accumulation.h"

#include <algorithm>
#include <array>
#include <cstring>

namespace toyrt {

namespace {

// Ranked (id, coverage) pairs of one pixel and kind merged with weights wa and wp.
void merge_cryptomatte(float* into, const float* pass, int depth, float wa, float wp) {
  std::array<float, 4 * kCryptomatteMaxDepth> ids{}, cover{};
  int n = 0;
  auto add = [&](float id, float c) {
    if (c <= 0.0f) return;
    for (int k = 0; k < n; ++k)
      if (std::memcmp(&ids[k], &id, sizeof id) == 0) {  // ids are hashes: compare the bits
        cover[k] += c;
        return;
      }
    ids[n] = id;
    cover[n++] = c;
  };
  for (int k = 0; k < depth; ++k) add(into[2 * k], into[2 * k + 1] * wa);
  for (int k = 0; k < depth; ++k) add(pass[2 * k], pass[2 * k + 1] * wp);
  // Highest coverage first; ties keep the accumulated order (a stable insertion sort of <= 32).
  for (int i = 1; i < n; ++i)
    for (int j = i; j > 0 && cover[j] > cover[j - 1]; --j) {
      std::swap(cover[j], cover[j - 1]);
      std::swap(ids[j], ids[j - 1]);
    }
  for (int k = 0; k < depth; ++k) {
    into[2 * k] = k < n ? ids[k] : 0.0f;
    into[2 * k + 1] = k < n ? cover[k] : 0.0f;
  }
}

}  // namespace

void accumulate_tile(RenderResult& into, std::vector<uint32_t>& counts_into, const RenderResult& pass,
                     const std::vector<uint32_t>& counts_pass, const Tile& tile, int cryptomatte_depth) {
  for (int j = tile.y; j < tile.y + tile.height; ++j)
    for (int i = tile.x; i < tile.x + tile.width; ++i) {
      const size_t index = size_t(j) * size_t(into.width) + size_t(i);
      const uint32_t na = counts_into[index], np = counts_pass[index];
      if (np == 0) continue;  // converged before this pass: nothing new
      const float wp = float(np) / float(na + np), wa = 1.0f - wp;
      for (int c = 0; c < 4; ++c) {
        float& v = into.rgba[index * 4 + c];
        v = wa * v + wp * pass.rgba[index * 4 + c];
      }
      for (size_t k = 0; k < kAovCount; ++k) {
        std::vector<float>& d = into.passes.data[k];
        if (d.empty()) continue;
        const size_t ch = size_t(aov_channels(Aov(k)));
        const float* src = &pass.passes.data[k][index * ch];
        float* dst = &d[index * ch];
        if (aov_from_first_sample(Aov(k))) {
          if (na == 0) std::copy(src, src + ch, dst);
        } else {
          for (size_t c = 0; c < ch; ++c) dst[c] = wa * dst[c] + wp * src[c];
        }
      }
      for (size_t k = 0; k < kCryptoKindCount; ++k) {
        std::vector<float>& d = into.passes.cryptomatte[k];
        if (d.empty()) continue;
        const size_t ch = size_t(2 * cryptomatte_depth);
        merge_cryptomatte(&d[index * ch], &pass.passes.cryptomatte[k][index * ch], cryptomatte_depth, wa, wp);
      }
      counts_into[index] = na + np;
    }
}

}  // namespace toyrt
