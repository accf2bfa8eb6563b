// The closed set of materials, dispatched statically (std::variant): the integrator visits the
// material once per hit with one case per type (an Overloaded set, core/overloaded.h), so a type
// added here without its case in the integrator fails to compile, and a scene without refractive
// materials never runs refraction code.
#pragma once

#include "core/overloaded.h"
#include "materials/lambert.h"
#include "materials/refraction.h"

#include <cstdint>
#include <string>
#include <variant>

namespace toyrt {

using Material = std::variant<Lambert, PerfectRefraction, FresnelDielectric>;

// The texture a material reads (-1: none).
inline int32_t texture_of(const Material& material) {
  return std::visit(
      Overloaded{[](const Lambert& m) { return m.texture; }, [](const PerfectRefraction&) { return int32_t(-1); },
                 [](const FresnelDielectric&) { return int32_t(-1); }},
      material);
}

// A material from Blender-facing settings: kind "diffuse" (Lambert with `color`, linear RGB >= 0,
// or texture `texture`; -1: none), "refraction" (PerfectRefraction) or "glass"
// (FresnelDielectric), both with `ior`. Throws std::invalid_argument for another kind or a bad
// value. Texture ids are checked against the scene's textures by Scene::add_material.
inline constexpr const char* kDefaultMaterialKind = "diffuse";
Material make_material(const std::string& kind, const Vec3& color, int64_t texture, float ior);

}  // namespace toyrt
