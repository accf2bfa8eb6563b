// The closed set of materials, dispatched statically (std::variant), as lights are: the variant
// is the one table of material types. A new type is its own materials/<x>.{h,cpp} and one entry
// below. Each type provides
//     static constexpr const char* kType, kParams;  static X from_params(const Params&);  (make_material)
//     Scatter scatter(const X&, const ShadingPoint&, const MaterialContext&);     (the integrator)
//     int32_t texture_index(const X&);   // the texture it reads, -1: none         (the scene's check)
// and a type without them fails to compile here or in the integrator's generic visit; a scene
// without refractive materials never runs refraction code.
#pragma once

#include "core/type_table.h"
#include "materials/diffuse_glossy.h"
#include "materials/glossy.h"
#include "materials/lambert.h"
#include "materials/principled.h"
#include "materials/refraction.h"

#include <cstdint>
#include <string>
#include <string_view>
#include <variant>

namespace toyrt {

using Material = std::variant<Lambert, PerfectRefraction, FresnelDielectric, Glossy, DiffuseGlossy, Principled>;

// The texture a material reads (-1: none).
inline int32_t texture_of(const Material& material) {
  return std::visit([](const auto& m) { return texture_index(m); }, material);
}

// A material of kind `kind` ("diffuse", "refraction", "glass", "glossy", "diffuse_glossy", "principled": the kTypes)
// from its parameters. Throws std::invalid_argument for another kind (listing the known ones), a bad value or an
// argument the kind does not read. Texture ids are checked against the scene's textures by Scene::add_material.
inline constexpr const char* kDefaultMaterialKind = Lambert::kType;  // Blender's default surface
inline Material make_material(std::string_view kind, const Params& params) {
  return make_from_params<Material>(kind, params, "material", "kind");
}

}  // namespace toyrt
