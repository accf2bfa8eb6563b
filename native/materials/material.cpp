#include "materials/material.h"

#include <cstdint>
#include <stdexcept>

namespace toyrt {

Material make_material(const std::string& kind, const Vec3& color, int64_t texture, float ior) {
  if (kind == "diffuse") {
    if (!is_finite(color) || color.x < 0.0f || color.y < 0.0f || color.z < 0.0f)
      throw std::invalid_argument("color must be finite and >= 0");
    // Ids the scene does not have are refused by Scene::add_material, with its texture count.
    if (texture < INT32_MIN || texture > INT32_MAX)
      throw std::invalid_argument("unknown texture id " + std::to_string(texture));
    return Lambert{color, int32_t(texture)};
  }
  if (kind == "refraction") return PerfectRefraction::make(ior);
  if (kind == "glass") return FresnelDielectric::make(ior);
  throw std::invalid_argument("material kind must be 'diffuse', 'refraction' or 'glass', got '" + kind + "'");
}

}  // namespace toyrt
