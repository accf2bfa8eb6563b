// The diffuse material (Blender's Diffuse BSDF with roughness 0, or a Principled BSDF reduced to
// its base colour): f = albedo / pi, the albedo a constant or an image texture's RGB at the hit's
// UV (the Image Texture node wired to the colour input replaces the constant).
#pragma once

#include "materials/texture.h"
#include "sampling/warp.h"

#include <cstdint>
#include <vector>

namespace toyrt {

struct Lambert {
  Vec3 albedo{0.8f};     // linear RGB, used when there is no texture
  int32_t texture = -1;  // index into the scene's textures; -1: constant albedo
};

// The albedo at texture coordinates uv (only textured materials look the texture up).
inline Vec3 lambert_albedo(const Lambert& m, const std::vector<Texture>& textures, const Vec2& uv) {
  if (m.texture < 0) return m.albedo;
  return Vec3(textures[size_t(m.texture)].lookup(uv));
}

// The BRDF value for directions on the same side as the normal (the integrator checks sides).
inline Vec3 lambert_f(const Vec3& albedo) { return albedo * kInvPi; }

}  // namespace toyrt
