// What a material emits, beside its BSDF: Blender's Emission shader (colour x strength, with no
// BSDF: a black surface that glows) and Principled BSDF's Emission. Kept beside the material,
// not inside the Material variant, because any material can emit, as any Cycles shader can add
// an emission closure to its BSDFs. The scene turns the triangles of emitting materials into
// lights at commit (lights/mesh_emitters.h).
#pragma once

#include "core/math.h"
#include "lights/mesh_emitters.h"

#include <cmath>
#include <stdexcept>

namespace toyrt {

struct MaterialEmission {
  Vec3 radiance{0.0f};  // W / (m^2 sr), both sides: colour x strength
  // Sampled as a light (Cycles 3.x material.cycles.sample_as_light, 4.x+ emission_sampling other
  // than None); false: seen by rays that hit it, lighting nothing by shadow rays.
  bool sampled = true;
  EmitterSides sides = EmitterSides::Both;  // which sides shadow rays sample (4.x+ Front / Back)

  bool emits() const { return radiance.x > 0.0f || radiance.y > 0.0f || radiance.z > 0.0f; }
  bool operator==(const MaterialEmission& o) const {
    return radiance == o.radiance && sampled == o.sampled && sides == o.sides;
  }

  // Throws std::invalid_argument for a non-finite or negative radiance.
  void check() const {
    if (!is_finite(radiance) || glm::any(glm::lessThan(radiance, Vec3(0.0f))))
      throw std::invalid_argument("emission must be finite and >= 0");
  }
};

}  // namespace toyrt
