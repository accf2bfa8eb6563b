#include "scene/mesh_shading.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace toyrt {

int32_t MeshShading::check(size_t triangles) const {
  auto sized = [&](size_t size, size_t per_triangle, const char* name) {
    if (size != 0 && size != per_triangle * triangles)
      throw std::invalid_argument(std::string(name) + " must hold " + std::to_string(per_triangle) +
                                  " values per triangle (" + std::to_string(per_triangle * triangles) + "), got " +
                                  std::to_string(size));
  };
  sized(corner_normals.size(), 3, "normals");
  sized(corner_uvs.size(), 3, "uvs");
  sized(corner_tangents.size(), 3, "tangents");
  sized(material_ids.size(), 1, "material_ids");
  for (const Vec3& n : corner_normals)
    if (!is_finite(n)) throw std::invalid_argument("normals holds a non-finite value");
  for (const Vec2& uv : corner_uvs)
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) throw std::invalid_argument("uvs holds a non-finite value");
  for (const glm::vec4& t : corner_tangents)
    if (!std::isfinite(t.x) || !std::isfinite(t.y) || !std::isfinite(t.z) || !std::isfinite(t.w))
      throw std::invalid_argument("tangents holds a non-finite value");
  int32_t most = -1;
  for (int32_t id : material_ids) {
    if (id < 0) throw std::invalid_argument("material_ids must be >= 0");
    most = std::max(most, id);
  }
  return most;
}

}  // namespace toyrt
