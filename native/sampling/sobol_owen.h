// The per-pixel low-discrepancy pattern: the first two dimensions of the Sobol sequence, Owen
// scrambled with a hash and shuffled per pixel (Burley 2020, "Practical Hash-based Owen
// Scrambling", JCGT 9(4)).
//
// Why this pattern: the 2D Sobol points are a (0,2)-sequence in base 2, so every aligned block of
// 2^m consecutive points is a (0,m,2)-net: each of the 2^m elementary boxes of size
// 2^-a x 2^-(m-a) holds exactly one point, for every a (stratified in all aspect ratios at once,
// and progressively: any power of two of samples is stratified). Owen scrambling (random flips
// of each bit, the flip depending on the more significant bits) keeps that property, makes the
// points uniformly distributed individually (so estimates stay unbiased) and gives smooth
// integrands an error variance of O(N^-3) instead of O(N^-1). The scramble and the shuffle of the
// sample index are seeded by a hash of (pixel, dimension, seed): pixels and the 2D dimensions of
// one sample are decorrelated (Burley's "padding"), and no table or state is needed, so the
// pattern is counter based like rng.h. The index shuffle is itself a nested uniform scramble of
// the index bits, which maps each aligned block of 2^m indices onto an aligned block of 2^m: the
// first 2^m samples of a pixel remain a net.
#pragma once

#include "sampling/rng.h"
#include "sampling/warp.h"

#include <cstdint>

namespace toyrt {

// Swaps of neighbouring bits, pairs and nibbles, then the byte order (one bswap for the swaps of
// bytes and halves).
inline uint32_t reverse_bits(uint32_t x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4);
  return __builtin_bswap32(x);
}

// Laine and Karras's hash-based permutation, with the constants Burley's paper gives: adding the
// seed and x ^= x * even_constant only propagate information from less to more significant bits,
// so each bit is flipped by a function of the bits below it.
inline uint32_t laine_karras_permutation(uint32_t x, uint32_t seed) {
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return x;
}

// Owen scrambling of a 32-bit fraction: reversed, a bit's flip depends on the more significant
// bits of the fraction, which is Owen's nested uniform scramble.
inline uint32_t nested_uniform_scramble(uint32_t x, uint32_t seed) {
  return reverse_bits(laine_karras_permutation(reverse_bits(x), seed));
}

// Sobol dimension 1 (primitive polynomial x + 1, direction numbers v_0 = 1/2,
// v_k = v_{k-1} ^ (v_{k-1} >> 1), i.e. Pascal's triangle mod 2), bit-reversed: bit i is the sum
// over the index's set bits j of C(j, i) mod 2. As polynomials over GF(2) (bit i the coefficient
// of z^i) that is X(1 + z), X composed with 1 + z (not multiplied by it), block by block: in each
// block of 2s bits, whose halves are already done, (1 + z)^s = 1 + z^s adds the upper half into
// the lower one; s = 1, 2, 4, 8, 16. Five shifts where summing the direction numbers took a step,
// and a branch, for every bit.
inline uint32_t sobol_dimension1_reversed(uint32_t index) {
  index ^= (index >> 1) & 0x55555555u;
  index ^= (index >> 2) & 0x33333333u;
  index ^= (index >> 4) & 0x0F0F0F0Fu;
  index ^= (index >> 8) & 0x00FF00FFu;
  index ^= (index >> 16) & 0x0000FFFFu;
  return index;
}

// Sobol dimension 0 (van der Corput in base 2) and dimension 1, as 32-bit fractions (what the
// samplers below compute, without the reversals that cancel; tests/native/sampling_test.cpp).
inline uint32_t sobol_dimension0(uint32_t index) { return reverse_bits(index); }
inline uint32_t sobol_dimension1(uint32_t index) { return reverse_bits(sobol_dimension1_reversed(index)); }

// Sample `sample` of pixel `pixel` in the 2D dimension `dimension` (0: position in the pixel, then
// one per 2D decision), a point of [0, 1)^2: nested_uniform_scramble(sobol_dimensionK(index), ...),
// written without the two bit reversals that cancel (the scramble reverses its input first).
inline Vec2 sobol_owen_2d(uint32_t pixel, uint32_t sample, uint32_t dimension, uint32_t seed) {
  const uint32_t key = hash_keys(pixel, dimension, seed, 0x736f626cu);
  const uint32_t index = nested_uniform_scramble(sample, key);
  const uint32_t x = reverse_bits(laine_karras_permutation(index, pcg_hash(key ^ 0x1u)));
  const uint32_t y = reverse_bits(laine_karras_permutation(sobol_dimension1_reversed(index), pcg_hash(key ^ 0x2u)));
  return {bits_to_unit_float(x), bits_to_unit_float(y)};
}

// The 1D counterpart (scrambled van der Corput): stratified in 1D for choices such as a light.
inline float sobol_owen_1d(uint32_t pixel, uint32_t sample, uint32_t dimension, uint32_t seed) {
  const uint32_t key = hash_keys(pixel, dimension, seed, 0x31646f77u);
  const uint32_t index = nested_uniform_scramble(sample, key);
  return bits_to_unit_float(reverse_bits(laine_karras_permutation(index, pcg_hash(key ^ 0x3u))));
}

}  // namespace toyrt
