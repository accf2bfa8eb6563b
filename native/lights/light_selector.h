// Picks one light per shading point with probability proportional to its importance there
// (light_importance: intensity over distance^2 with cosine bounds), so the cost of direct
// lighting is one shadow ray whatever the light count, and lights that cannot reach the point
// (behind it, or facing away) are never chosen. The one-sample estimate
//     contribution(chosen light) / probability
// is unbiased because every light that can contribute has a positive importance.
//
// It walks all lights twice per call (sum, then the pick), with no allocation: fine for tens of
// lights. Thousands would want a light tree (Conty Estevez and Kulla 2018), which can replace
// this behind the same two calls.
#pragma once

#include "lights/light.h"

#include <cstdint>
#include <vector>

namespace toyrt {

struct LightSelection {
  int32_t index = -1;        // -1: no light can contribute at this point
  float probability = 0.0f;  // of choosing `index`
  bool found() const { return index >= 0; }
};

struct LightSelector {
  const Light* lights = nullptr;  // not owned: the scene's lights, which must outlive the selector
  size_t count = 0;

  LightSelector() = default;
  explicit LightSelector(const std::vector<Light>& all) : lights(all.data()), count(all.size()) {}

  // The light for uniform number u in [0, 1) at point p with normal n (n = 0: no cosine bound).
  LightSelection select(const Vec3& p, const Vec3& n, float u) const;
  // The probability that select() picks `index` at (p, n), e.g. for multiple importance sampling.
  float probability(const Vec3& p, const Vec3& n, size_t index) const;
};

}  // namespace toyrt
