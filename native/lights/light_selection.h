// What a light selector (lights/light_selector.h, lights/light_tree.h) answers: the light chosen
// at a shading point and the probability of that choice.
#pragma once

#include <cstdint>

namespace toyrt {

struct LightSelection {
  int32_t index = -1;        // -1: no light can contribute at this point
  float probability = 0.0f;  // of choosing `index`
  // The uniform number rescaled into the chosen light's share, in [0, 1): what is left of it for
  // sampling a point on that light (the emissive triangles draw their point from it).
  float remainder = 0.0f;
  bool found() const { return index >= 0; }
};

}  // namespace toyrt
