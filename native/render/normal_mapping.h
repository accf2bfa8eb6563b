// The shading normal at a hit whose material has a Normal Map node (materials/normal_map.h): the
// map's texel read at the hit's UV, in the frame of the mesh's interpolated tangents and smooth
// normal (tangent space), or as an object- or world-space vector; then kept from reflecting the
// view below the surface. Called by the integrator only in scenes with a normal map
// (Scene::any_normal_map), so other scenes pay one flag test per hit.
#pragma once

#include "core/math.h"
#include "core/ray.h"
#include "materials/scatter.h"
#include "scene/scene.h"

#include <cstdint>

namespace toyrt {

// ng, ns: the hit's unit geometric and smooth normals, world space, as stored (ns on ng's side);
// wo: unit, back along the ray; material: an id (-1 or past the materials: the default grey, no
// normal map). Returns the new unit shading normal, on
// ng's side as ns is; ns itself for a material without a normal map and, in tangent space, for
// a mesh sent without tangents (Cycles falls back to the unbent normal there too).
// footprint: the ray cone's width at the hit in metres (camera/ray_cone.h), read only by bump maps
// that difference over it (MaterialNormalMap::bump_footprint); 0 gives them the slope at the point.
Vec3 normal_mapped(const Scene& scene, const Hit& hit, int32_t material, const Vec3& wo, const Vec3& ng, const Vec3& ns,
                   const Vec2& uv, float footprint = 0.0f);

// Cycles' bump shadowing (materials/bump_shadowing.h) on the diffuse part of a normal-mapped
// hit's answer `sc`, carried by the integrator's Burley path (Scatter::burley, BurleyDiffuse):
// smooth and bent are the normals before and after the map, both on wo's side.
inline void shadow_bumps(const Scene& scene, int32_t material, Scatter& sc, const Vec3& smooth, const Vec3& bent,
                         const Vec3& wo) {
  if (material < 0 || size_t(material) >= scene.normal_maps().size() || smooth == bent) return;
  const MaterialNormalMap& map = scene.normal_maps()[size_t(material)];
  if (!map.active() || map.shadowing == BumpShadowing::None) return;
  if (sc.kind != Scatter::Kind::Diffuse &&
      !((sc.kind == Scatter::Kind::Glossy || sc.kind == Scatter::Kind::Mixture) && sc.f != Vec3(0.0f)))
    return;
  if (!sc.burley) {
    sc.burley = true;
    sc.retro = BurleyDiffuse{bent, wo, 0.0f, false};
  }
  sc.retro.bump = map.shadowing;
  sc.retro.smooth = smooth;
}

}  // namespace toyrt
