// Shading attributes of one mesh, by triangle corner (Blender's loop triangles), kept beside the
// mesh's geometry in Scene: each array is empty when the mesh does not have it. Flat shading
// uses the geometric normal.
#pragma once

#include "core/math.h"
#include "sampling/warp.h"  // Vec2

#include <cstdint>
#include <vector>

namespace toyrt {

struct MeshShading {
  std::vector<Vec3> corner_normals;  // 3 per triangle, object space (smooth or custom normals)
  std::vector<Vec2> corner_uvs;      // 3 per triangle
  // 3 per triangle, object space: the MikkTSpace tangent (xyz, unit) and the bitangent's sign
  // (w, +-1) of the UV map a Normal Map node reads; sent only for meshes whose material has one.
  std::vector<glm::vec4> corner_tangents;
  std::vector<int32_t> material_ids;  // 1 per triangle, into Scene::materials()

  // Throws std::invalid_argument unless every array is empty or sized for `triangles`, normals,
  // uvs and tangents are finite and material ids are >= 0. Returns the largest material id (-1: none), which
  // the scene keeps so a render checks ids against the materials without walking the triangles.
  int32_t check(size_t triangles) const;
};

}  // namespace toyrt
