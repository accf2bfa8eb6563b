#include "render/normal_mapping.h"

namespace toyrt {
namespace {

// The bent normal (any length) blended with ns by the strength, then on ng's side, lifted where
// the map asks for it.
Vec3 lifted(const MaterialNormalMap& map, const Vec3& bent, const Vec3& ng, const Vec3& wo, const Vec3& ns) {
  const Vec3 unit = blend_normal_strength(map, bent, ns);
  if (!map.lift) return glm::dot(unit, ng) >= 0.0f ? unit : -unit;  // the same normal, on ng's side
  // The reflection test on the side the ray arrives from, as Cycles' normals are turned there.
  const float side = glm::dot(ng, wo) >= 0.0f ? 1.0f : -1.0f;
  return side * valid_reflection_normal(side * ng, wo, side * unit);
}

// A Bump node's normal at the hit: the triangle's world edges as the tangent vectors, the
// height's change along each from the image's UV gradient (forward differences of a hundredth of
// a texel: the slope of the bilinear patch the point is in, as Cycles 4.4+ takes it). With
// bump_footprint and a footprint w > 0, Cycles 3.x's differences over the footprint instead
// (materials/normal_map.h). ns for a mesh without UVs or with degenerate ones. ng: the unit geometric
// normal on the ray's side, as Cycles' Ng.
Vec3 bumped(const Scene& scene, const Instance& inst, const MeshShading& sh, const MaterialNormalMap& map,
            const Hit& hit, const Vec3& ns, const Vec3& ng, const Vec2& uv, float footprint) {
  const size_t c = 3 * size_t(hit.prim);
  if (sh.corner_uvs.size() < c + 3) return ns;
  const Vec2 d1 = sh.corner_uvs[c + 1] - sh.corner_uvs[c], d2 = sh.corner_uvs[c + 2] - sh.corner_uvs[c];
  if (d1.x * d2.y - d1.y * d2.x == 0.0f) return ns;
  const Mesh& mesh = scene.mesh(inst.mesh);
  const Triangle& tri = mesh.triangles()[size_t(hit.prim)];
  const Vec3 p0 = mesh.vertices()[tri.x];
  const glm::mat3 to_world(inst.to_world);
  const Vec3 e1 = to_world * (mesh.vertices()[tri.y] - p0), e2 = to_world * (mesh.vertices()[tri.z] - p0);
  const Texture& image = scene.textures()[size_t(map.texture)];
  if (map.bump_footprint && footprint > 0.0f) {
    // Cycles 3.x: the footprint's tangents dx = w a, dy = w b, and the UV offsets that move the
    // point by them on the triangle's plane (its differential_dudv: e1 s + e2 t = dx, solved by
    // the plane's Gram matrix), the image read there and at the point.
    Vec3 a, b;
    footprint_axes(ng, a, b);
    const Vec3 dx = footprint * a, dy = footprint * b;
    const float g11 = glm::dot(e1, e1), g12 = glm::dot(e1, e2), g22 = glm::dot(e2, e2);
    const float det = g11 * g22 - g12 * g12;
    if (det > 0.0f) {
      auto uv_step = [&](const Vec3& d) {
        const float r1 = glm::dot(e1, d), r2 = glm::dot(e2, d);
        return ((g22 * r1 - g12 * r2) * d1 + (g11 * r2 - g12 * r1) * d2) / det;
      };
      const float h = bump_height(map, image.lookup(uv));
      const float hx = bump_height(map, image.lookup(uv + uv_step(dx))) - h;
      const float hy = bump_height(map, image.lookup(uv + uv_step(dy))) - h;
      return bump_normal(map, ns, dx, dy, hx, hy);
    }
  }
  const float du = 0.01f / float(image.width), dv = 0.01f / float(image.height);
  const float h = bump_height(map, image.lookup(uv));
  const float hu = (bump_height(map, image.lookup(uv + Vec2(du, 0.0f))) - h) / du;
  const float hv = (bump_height(map, image.lookup(uv + Vec2(0.0f, dv))) - h) / dv;
  return bump_normal(map, ns, e1, e2, hu * d1.x + hv * d1.y, hu * d2.x + hv * d2.y);
}

}  // namespace

Vec3 normal_mapped(const Scene& scene, const Hit& hit, int32_t material, const Vec3& wo, const Vec3& ng, const Vec3& ns,
                   const Vec2& uv, float footprint) {
  if (material < 0 || size_t(material) >= scene.normal_maps().size()) return ns;
  const MaterialNormalMap& map = scene.normal_maps()[size_t(material)];
  if (!map.active()) return ns;
  const Instance& inst = scene.instance(uint32_t(hit.instance));
  const MeshShading& sh = scene.shading(inst.mesh);
  if (map.bump) {
    // Cycles bumps the normal turned to the ray's side (a back face's heights rise towards the
    // viewer); the result goes back to ns's side for the strength and the lift.
    const float side = glm::dot(ng, wo) >= 0.0f ? 1.0f : -1.0f;
    return lifted(map, side * bumped(scene, inst, sh, map, hit, side * ns, side * ng, uv, footprint), ng, wo, ns);
  }
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
  return lifted(map, bent, ng, wo, ns);
}

}  // namespace toyrt
