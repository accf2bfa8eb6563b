#include "render/normal_mapping.h"

namespace toyrt {

Vec3 normal_mapped(const Scene& scene, const Hit& hit, int32_t material, const Vec3& wo, const Vec3& ng, const Vec3& ns,
                   const Vec2& uv) {
  if (material < 0 || size_t(material) >= scene.normal_maps().size()) return ns;
  const MaterialNormalMap& map = scene.normal_maps()[size_t(material)];
  if (!map.active()) return ns;
  const Instance& inst = scene.instance(uint32_t(hit.instance));
  const MeshShading& sh = scene.shading(inst.mesh);
  const Vec3 n = normal_map_vector(map, Vec3(scene.textures()[size_t(map.texture)].lookup(uv)));
  // Object-space vectors go to world space by the inverse transpose (to_object is the inverse).
  const glm::mat3 normal_matrix = glm::transpose(glm::mat3(inst.to_object));
  Vec3 bent = n;
  if (map.space == NormalMapSpace::Tangent) {
    if (sh.corner_tangents.empty()) return ns;
    const size_t c = 3 * size_t(hit.prim);
    const float w = 1.0f - hit.u - hit.v;
    // Interpolated, not normalised: Cycles reads the attributes so.
    const glm::vec4 t =
        w * sh.corner_tangents[c] + hit.u * sh.corner_tangents[c + 1] + hit.v * sh.corner_tangents[c + 2];
    Vec3 smooth;
    if (!sh.corner_normals.empty()) {
      smooth = w * sh.corner_normals[c] + hit.u * sh.corner_normals[c + 1] + hit.v * sh.corner_normals[c + 2];
    } else {  // flat: the triangle's own normal, object space
      const Mesh& mesh = scene.mesh(inst.mesh);
      const Triangle& tri = mesh.triangles()[size_t(hit.prim)];
      const Vec3 p0 = mesh.vertices()[tri.x];
      smooth = glm::cross(mesh.vertices()[tri.y] - p0, mesh.vertices()[tri.z] - p0);
      const float len2 = glm::dot(smooth, smooth);
      if (len2 > 0.0f) smooth /= std::sqrt(len2);
    }
    bent = normal_matrix * tangent_space_normal(map, n, Vec3(t), t.w, smooth);
  } else if (map.space == NormalMapSpace::Object || map.space == NormalMapSpace::BlenderObject) {
    bent = normal_matrix * n;
  }
  const Vec3 unit = blend_normal_strength(map, bent, ns);
  if (!map.lift) return glm::dot(unit, ng) >= 0.0f ? unit : -unit;  // the same normal, on ng's side
  // The reflection test on the side the ray arrives from, as Cycles' normals are turned there.
  const float side = glm::dot(ng, wo) >= 0.0f ? 1.0f : -1.0f;
  return side * valid_reflection_normal(side * ng, wo, side * unit);
}

}  // namespace toyrt
