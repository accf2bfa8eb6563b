// Counter-based random numbers: every value is a hash of (pixel, sample, dimension, seed), so a
// render draws the same numbers whatever the thread count or tile order, and no generator state
// travels between samples or threads. `dimension` numbers the random decisions of one sample
// (pixel position, light choice, point on the light, ...); the integrator assigns them.
#pragma once

#include <cstdint>

namespace toyrt {

// The PCG hash: one step of PCG's LCG followed by its RXS-M-XS output permutation, a bijection
// of 32-bit integers with full avalanche (Jarzynski and Olano 2020, "Hash Functions for GPU
// Rendering", JCGT 9(3), which recommends it for its quality per operation).
inline uint32_t pcg_hash(uint32_t v) {
  const uint32_t state = v * 747796405u + 2891336453u;
  const uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

// Several keys into one hash by nesting, pcg(x ^ pcg(y)), the combination the same paper uses
// for multi-dimensional inputs.
inline uint32_t hash_keys(uint32_t a, uint32_t b) { return pcg_hash(b ^ pcg_hash(a)); }
inline uint32_t hash_keys(uint32_t a, uint32_t b, uint32_t c) { return pcg_hash(c ^ hash_keys(a, b)); }
inline uint32_t hash_keys(uint32_t a, uint32_t b, uint32_t c, uint32_t d) { return pcg_hash(d ^ hash_keys(a, b, c)); }

// The top 24 bits as a float in [0, 1): every value is exact, and 1 is never returned.
inline float bits_to_unit_float(uint32_t bits) { return float(bits >> 8) * 0x1p-24f; }

// A uniform float in [0, 1) for one (pixel, sample, dimension, seed). `pixel` is the pixel's
// index in the full image (y * width + x), so a border render draws the same numbers as a full one.
inline float random_float(uint32_t pixel, uint32_t sample, uint32_t dimension, uint32_t seed) {
  return bits_to_unit_float(hash_keys(pixel, sample, dimension, seed));
}

}  // namespace toyrt
