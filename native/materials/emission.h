// What a material emits, beside its BSDF: Blender's Emission shader (colour x strength, with no
// BSDF: a black surface that glows) and Principled BSDF's Emission. Kept beside the material,
// not inside the Material variant, because any material can emit, as any Cycles shader can add
// an emission closure to its BSDFs. The scene turns the triangles of emitting materials into
// lights at commit (lights/mesh_emitters.h).
//
// The colour may be an Image Texture's Color (Blender's Emission Color linked to one): the
// emitted radiance is then `radiance` (the strength) times the image's RGB at the point's UV,
// wherever rays meet it or shadow rays sample it (emitted()).
#pragma once

#include "core/math.h"
#include "lights/mesh_emitters.h"
#include "materials/texture.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace toyrt {

struct MaterialEmission {
  Vec3 radiance{0.0f};  // W / (m^2 sr), both sides: colour x strength
  // Sampled as a light (Cycles 3.x material.cycles.sample_as_light, 4.x+ emission_sampling other
  // than None); false: seen by rays that hit it, lighting nothing by shadow rays.
  bool sampled = true;
  EmitterSides sides = EmitterSides::Both;  // which sides shadow rays sample (4.x+ Front / Back)
  int32_t texture = -1;                     // the colour's image (a scene texture id), or -1: none

  bool emits() const { return radiance.x > 0.0f || radiance.y > 0.0f || radiance.z > 0.0f; }
  bool operator==(const MaterialEmission& o) const {
    return radiance == o.radiance && sampled == o.sampled && sides == o.sides && texture == o.texture;
  }

  // Throws std::invalid_argument for a non-finite or negative radiance or an unknown texture.
  void check(size_t textures) const {
    if (!is_finite(radiance) || glm::any(glm::lessThan(radiance, Vec3(0.0f))))
      throw std::invalid_argument("emission must be finite and >= 0");
    if (texture < -1 || texture >= int64_t(textures))
      throw std::invalid_argument("unknown emission_texture id " + std::to_string(texture) + " (the scene has " +
                                  std::to_string(textures) + " textures)");
  }
};

// The radiance `e` emits at a point of texture coordinates uv (both sides).
inline Vec3 emitted(const MaterialEmission& e, const std::vector<Texture>& textures, const Vec2& uv) {
  if (e.texture < 0) return e.radiance;
  return e.radiance * Vec3(textures[size_t(e.texture)].lookup(uv));
}

}  // namespace toyrt
