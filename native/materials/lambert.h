// The diffuse material (Blender's Diffuse BSDF with roughness 0, or a Principled BSDF reduced to
// its base colour): f = albedo / pi, the albedo a constant or an image texture's RGB at the hit's
// UV (the Image Texture node wired to the colour input replaces the constant).
//
// Parameters (add_material('diffuse', ...)): color ((0.8, 0.8, 0.8), linear RGB >= 0), texture
// (-1: none; an id from add_texture, checked against the scene's textures by Scene).
//
// scatter() is inline: every diffuse hit of every render runs it, and a Lambert-only scene must
// cost no more than before the material interface was generic.
#pragma once

#include "core/params.h"
#include "materials/scatter.h"
#include "materials/texture.h"
#include "sampling/warp.h"

#include <cstdint>
#include <vector>

namespace toyrt {

struct Lambert {
  static constexpr const char* kType = "diffuse";
  static constexpr const char* kParams = "color (linear RGB, (0.8, 0.8, 0.8)), texture (id from add_texture, -1: none)";
  Vec3 albedo{0.8f};     // linear RGB, used when there is no texture
  int32_t texture = -1;  // index into the scene's textures; -1: constant albedo

  static Lambert from_params(const Params& params) {
    const Lambert d;
    return Lambert{params.color("color", d.albedo), int32_t(params.integer("texture", d.texture))};
  }
};

// The albedo at texture coordinates uv (only textured materials look the texture up).
inline Vec3 lambert_albedo(const Lambert& m, const std::vector<Texture>& textures, const Vec2& uv) {
  if (m.texture < 0) return m.albedo;
  return Vec3(textures[size_t(m.texture)].lookup(uv));
}

// The BRDF value for directions on the same side as the normal (the integrator checks sides).
inline Vec3 lambert_f(const Vec3& albedo) { return albedo * kInvPi; }

inline Scatter scatter(const Lambert& m, const ShadingPoint& s, const MaterialContext& ctx) {
  return Scatter::diffuse(lambert_f(lambert_albedo(m, *ctx.textures, s.uv)));
}
inline int32_t texture_index(const Lambert& m) { return m.texture; }

}  // namespace toyrt
