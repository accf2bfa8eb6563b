#include "lights/light_selector.h"

namespace toyrt {

LightSelection LightSelector::select_linear(const Vec3& p, const Vec3& n, float u, uint8_t set) const {
  float total = 0.0f;
  for (size_t i = 0; i < count; ++i) total += weight(i, p, n, set);
  LightSelection chosen;
  if (!(total > 0.0f)) return chosen;
  // The second pass repeats the first pass's sums in the same order, so the running sum ends at
  // exactly `total`; u * total can round up to total, in which case the last candidate is kept.
  const float target = u * total;
  float running = 0.0f;
  for (size_t i = 0; i < count; ++i) {
    const float w = weight(i, p, n, set);
    if (w <= 0.0f) continue;
    running += w;
    chosen.index = int32_t(i);
    chosen.probability = w / total;
    if (target < running) break;
  }
  return chosen;
}

float LightSelector::probability_linear(const Vec3& p, const Vec3& n, size_t index, uint8_t set) const {
  if (index >= count) return 0.0f;
  float total = 0.0f;
  for (size_t i = 0; i < count; ++i) total += weight(i, p, n, set);
  return total > 0.0f ? weight(index, p, n, set) / total : 0.0f;
}

}  // namespace toyrt
