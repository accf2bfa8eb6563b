// The shading normal at a hit whose material has a Normal Map node (materials/normal_map.h): the
// map's texel read at the hit's UV, in the frame of the mesh's interpolated tangents and smooth
// normal (tangent space), or as an object- or world-space vector; then kept from reflecting the
// view below the surface. Called by the integrator only in scenes with a normal map
// (Scene::any_normal_map), so other scenes pay one flag test per hit.
#pragma once

#include "core/math.h"
#include "core/ray.h"
#include "scene/scene.h"

#include <cstdint>

namespace toyrt {

// ng, ns: the hit's unit geometric and smooth normals, world space, as stored (ns on ng's side);
// wo: unit, back along the ray; material: a valid id. Returns the new unit shading normal, on
// ng's side as ns is; ns itself for a material without a normal map and, in tangent space, for
// a mesh sent without tangents (Cycles falls back to the unbent normal there too).
Vec3 normal_mapped(const Scene& scene, const Hit& hit, int32_t material, const Vec3& wo, const Vec3& ng, const Vec3& ns,
                   const Vec2& uv);

}  // namespace toyrt
