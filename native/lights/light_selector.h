// Picks one light per shading point with probability proportional to its importance there
// (light_importance: intensity over distance^2 with cosine bounds), so the cost of direct
// lighting is one shadow ray whatever the light count, and lights that cannot reach the point
// (behind it, or facing away) are never chosen. The one-sample estimate
//     contribution(chosen light) / probability
// is unbiased because every light that can contribute has a positive importance.
//
// It walks all lights twice per call (sum, then the pick), with no allocation: the cheapest for
// a few lights. Given the scene's light tree (lights/light_tree.h, built at commit for more than
// kLightTreeFrom lights) it asks the tree instead: O(log lights) per call, behind the same two calls.
// Given the lights' receiver sets (light linking), both leave out the lights that do not light
// the receiver's set, as Cycles does, instead of picking them for a zero contribution.
#pragma once

#include "lights/light.h"
#include "lights/light_linking.h"
#include "lights/light_selection.h"
#include "lights/light_tree.h"

#include <cstdint>
#include <vector>

namespace toyrt {

// Scenes with more lights than this select through the light tree, the others linearly: measured
// in docs/lights.md ("Light selection"). The tree's pick is cheaper from 32 lights on, but the
// linear weights are each light's own importance and the tree's cluster estimates are coarser (a
// variance 15 to 20x higher on an open floor), so at equal time the tree wins only from about
// 1,000 lights (the same error at 1,000, 1.9x better at 3,000, 2.6x at 10,000).
inline constexpr size_t kLightTreeFrom = 1000;

struct LightSelector {
  const Light* lights = nullptr;  // not owned: the scene's lights, which must outlive the selector
  size_t count = 0;
  const LightTree* tree = nullptr;  // built over exactly these lights, or null: the linear walk
  // Per light, the receiver sets it lights (lights/light_linking.h), or null: every light lights
  // every receiver. A tree given with these must have been given the same (set_receiver_sets).
  const uint64_t* sets = nullptr;

  LightSelector() = default;
  explicit LightSelector(const std::vector<Light>& all, const LightTree* over_all = nullptr,
                         const uint64_t* receiver_sets = nullptr)
      : lights(all.data()), count(all.size()), tree(over_all), sets(receiver_sets) {}

  // The light for uniform number u in [0, 1) at point p with normal n (n = 0: no cosine bound),
  // of a receiver in light-linking set `set`.
  LightSelection select(const Vec3& p, const Vec3& n, float u, uint8_t set = 0) const {
    return tree ? tree->select(lights, p, n, u, set) : select_linear(p, n, u, set);
  }
  // The probability that select() picks `index` at (p, n), e.g. for multiple importance sampling.
  float probability(const Vec3& p, const Vec3& n, size_t index, uint8_t set = 0) const {
    return tree ? tree->probability(lights, p, n, index, set) : probability_linear(p, n, index, set);
  }

  // The linear walk, proportional to each light's importance() (0 for a light not linked to `set`).
  LightSelection select_linear(const Vec3& p, const Vec3& n, float u, uint8_t set = 0) const;
  float probability_linear(const Vec3& p, const Vec3& n, size_t index, uint8_t set = 0) const;

 private:
  float weight(size_t i, const Vec3& p, const Vec3& n, uint8_t set) const {
    return sets && !in_light_sets(sets[i], set) ? 0.0f : light_importance(lights[i], p, n);
  }
};

}  // namespace toyrt
