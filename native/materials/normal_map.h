// Blender's Normal Map node on a material's Normal input: the shading normal bent by an image's
// texel, as Cycles' node computes it. Kept beside the material, as emission and transparency
// are (materials/emission.h, transparency.h), because every BSDF has a Normal socket.
//
// A texel c (linear, Non-Color) encodes n = 2 c - 1. In tangent space n is read in the frame of
// the interpolated MikkTSpace tangent T, the bitangent B = sign cross(N, T) and the interpolated
// (unnormalised) smooth normal N, all in object space: N' = normalize(n.x T + n.y B + n.z N),
// then carried to world space by the normal matrix. The DirectX convention stores -y. Object and
// world space read n directly (Blender's own "Blender Object/World" spaces flip y and z).
//
// Strength, per Blender version (Cycles' kernel, read in each): 3.x blends the world normals,
// N' = normalize(Ns + s (N' - Ns)) with s = max(strength, 0); since 4.x tangent space scales the
// texel instead, n.xy *= s and n.z = mix(1, n.z, clamp(s, 0, 1)) (object and world space keep
// the blend). A zero or non-finite result falls back to the smooth normal Ns.
//
// Below the surface: a bent normal can reflect the view direction under the geometric surface
// (a black or leaking pixel). valid_reflection_normal() turns it towards Ng just enough that the
// mirror direction of wo leaves the surface at a small positive elevation, as Cycles does for
// every closure normal (ensure_valid_reflection in 3.x, ensure_valid_specular_reflection in 4.x+).
//
// Blender's Bump node takes the map's place when `bump` is set: the texture is a height field h
// (the image's Rec. 709 luminance, or its alpha) and the normal follows Cycles' node. With two
// tangent vectors dx, dy of the surface and the heights' changes h_x, h_y along them,
// R_x = dy x N, R_y = N x dx, det = dx . R_x, and
// N' = normalize(|det| N - distance sign(det) ((h_x) R_x + (h_y) R_y)), blended with N by the
// strength as 3.x's normal maps are (distance < 0: Invert). To first order the result does not
// depend on dx, dy: Cycles 4.4+ takes the slope at the point, as TOYRT does by default with the
// triangle's edges and the height's change along them from its UV gradient (bump_normal();
// render/normal_mapping.cpp). Cycles before 4.4 differences the height over the ray's footprint
// instead (`bump_footprint`): dx, dy = w a, w b, with a, b = footprint_axes(Ng) and w the ray
// cone's width at the hit (camera/ray_cone.h), h_x = h(P + dx) - h(P), h_y = h(P + dy) - h(P).
#pragma once

#include "core/math.h"
#include "core/params.h"
#include "materials/bump_shadowing.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace toyrt {

enum class NormalMapSpace : uint8_t { Tangent, Object, World, BlenderObject, BlenderWorld };
enum class NormalStrength : uint8_t { Blend, Tangent };  // 3.x / 4.x+ (see above)

struct MaterialNormalMap {
  int32_t texture = -1;  // index into the scene's textures; -1: no normal map
  float strength = 1.0f;
  NormalMapSpace space = NormalMapSpace::Tangent;
  bool directx = false;  // the green channel stores -y (Blender 5.x's convention DirectX)
  NormalStrength strength_mode = NormalStrength::Tangent;
  BumpShadowing shadowing = BumpShadowing::Conty;  // of diffuse closures: 3.x Chiang, 4.x+ Conty
  // Lift the bent normal so the view's mirror stays above the surface (valid_reflection_normal):
  // Cycles 3.x does for every closure, 4.x+ only for glossy ones (not a Diffuse BSDF's).
  bool lift = true;
  bool bump = false;            // a Bump node's height field (above), not a Normal Map
  float distance = 1.0f;        // the Bump node's Distance, negated by Invert
  bool bump_alpha = false;      // the height is the image's alpha (else its luminance)
  bool bump_footprint = false;  // differences over the ray's footprint (Cycles before 4.4), not the slope

  // From add_material's keywords, which every material kind accepts: normal_map (a texture id,
  // -1: none), normal_strength (1), normal_space ('TANGENT', 'OBJECT', 'WORLD', 'BLENDER_OBJECT',
  // 'BLENDER_WORLD'), normal_convention ('OPENGL', 'DIRECTX'), normal_strength_mode ('tangent':
  // Blender 4.x+, 'blend': 3.x), normal_shadowing ('conty': 4.x+, 'chiang': 3.x, 'none'),
  // normal_lift (True). Or a Bump node: bump_map (a texture id), bump_strength (1),
  // bump_distance (1; negative: inverted), bump_channel ('gray': luminance, 'alpha'),
  // bump_footprint ('point': the slope at the point, Blender 4.4+; 'pixel': differences over the
  // ray's footprint, before 4.4), with normal_shadowing and normal_lift as above.
  // Throws std::invalid_argument for an unknown name, or for both a normal map and a bump map.
  static MaterialNormalMap from_params(const Params& params);

  bool active() const { return texture >= 0; }
  bool operator==(const MaterialNormalMap& o) const {
    return texture == o.texture && strength == o.strength && space == o.space && directx == o.directx &&
           strength_mode == o.strength_mode && shadowing == o.shadowing && lift == o.lift && bump == o.bump &&
           distance == o.distance && bump_alpha == o.bump_alpha && bump_footprint == o.bump_footprint;
  }
  // Throws std::invalid_argument for a non-finite strength or a texture id that is not -1 or
  // below `textures` (the scene's count).
  void check(size_t textures) const {
    if (!std::isfinite(strength)) throw std::invalid_argument("normal_strength must be finite");
    if (!std::isfinite(distance)) throw std::invalid_argument("bump_distance must be finite");
    if (texture < -1 || texture >= int64_t(textures))
      throw std::invalid_argument("unknown normal_map texture id " + std::to_string(texture) + " (the scene has " +
                                  std::to_string(textures) + " textures)");
  }
};

// The texel's vector n = 2 c - 1 in the map's own convention (DirectX: y negated; Blender's
// object and world spaces: y and z negated).
Vec3 normal_map_vector(const MaterialNormalMap& map, const Vec3& texel);

// Tangent space, object space: the bent normal from n (normal_map_vector), the interpolated
// tangent t with its bitangent sign, and the interpolated smooth normal n_smooth (all
// unnormalised). With NormalStrength::Tangent the strength scales n first. Zero when degenerate.
Vec3 tangent_space_normal(const MaterialNormalMap& map, Vec3 n, const Vec3& t, float sign, const Vec3& n_smooth);

// The bent world normal (any length) normalised, blended by strength with the smooth world
// normal ns (3.x's rule, and 4.x+'s in object and world space); ns for a zero or non-finite
// result. Unit out.
Vec3 blend_normal_strength(const MaterialNormalMap& map, const Vec3& bent, const Vec3& ns);

// The Bump node's normal (above) from the smooth unit normal n, two tangent vectors dx, dy and
// the height's changes hx, hy along them; n for a degenerate result. Unit, before the strength.
Vec3 bump_normal(const MaterialNormalMap& map, const Vec3& n, const Vec3& dx, const Vec3& dy, float hx, float hy);

// Cycles' two unit tangents a, b of a footprint around the unit normal ng (its make_orthonormals:
// a along (1, 1, 1) x ng, or (-1, 1, 1) x ng when ng's components are all equal; b = ng x a).
// Which pair matters: forward differences along them shift the bumps by half a footprint.
void footprint_axes(const Vec3& ng, Vec3& a, Vec3& b);

// The height a bump map reads from a texel (linear RGBA).
inline float bump_height(const MaterialNormalMap& map, const glm::vec4& t) {
  return map.bump_alpha ? t.w : 0.2126f * t.x + 0.7152f * t.y + 0.0722f * t.z;
}

// n turned towards ng, in the plane of both, until the mirror reflection of wo about it is at
// least min(0.9 dot(ng, wo), 0.01) above the surface (cosine to ng); n itself when it already
// is (-n if n is under the surface: the same mirror). ng, wo and n unit, wo on ng's side. Never
// NaN: ng when the equation has no usable root. The result is on ng's side.
Vec3 valid_reflection_normal(const Vec3& ng, const Vec3& wo, const Vec3& n);

}  // namespace toyrt
