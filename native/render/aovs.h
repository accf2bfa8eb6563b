// Render passes beside Combined (arbitrary output variables), defined as Cycles defines its data
// passes (kernel/film/data_passes.h) so a compositing setup made for Cycles reads them the same:
//   depth, object_index, material_index, position: from the first sample only (Cycles writes them
//     when the path's sample is 0); depth is the planar camera-space z, 1e10 where nothing is hit;
//     the others 0 there;
//   normal (world space, the shading normal turned to the viewer), diffuse_color (the diffuse
//     albedo), glossy_color (the glossy lobes' albedo as Cycles estimates it: glossy_color.h),
//     emission (the surface's and the lamps' the camera sees), environment (the world a camera
//     ray sees where it hits nothing): averaged over samples, 0 for samples that see none;
//   mist: 1 - mean over samples of (1 - mist(distance)), so 1 where nothing is hit.
// Only the first surface a camera ray hits counts, as in Cycles for opaque surfaces. A render that
// asks for no pass allocates and computes none of this (the integrator gets a null FirstHit).
// The Cryptomatte passes (cryptomatte.h) read the same first hit.
#pragma once

#include "core/math.h"
#include "materials/scatter.h"
#include "render/cryptomatte.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace toyrt {

struct Camera;

enum class Aov : uint8_t {
  Depth,
  Mist,
  Position,
  Normal,
  DiffuseColor,
  GlossyColor,
  Emission,
  Environment,
  ObjectIndex,
  MaterialIndex,
  Count
};
inline constexpr size_t kAovCount = size_t(Aov::Count);

// The name render(passes=...) takes ("depth", "diffuse_color", ...) and the float channels per pixel.
const char* aov_name(Aov aov);
int aov_channels(Aov aov);
// Whether the pass holds its first sample's value (depth, position, indices) rather than a mean.
bool aov_from_first_sample(Aov aov);
// Throws std::invalid_argument for a name that is none of aov_name's.
Aov parse_aov(const std::string& name);

// Blender's World mist settings (world.mist_settings), in its units: metres, falloff as Cycles'
// exponent (QUADRATIC 2, LINEAR 1, INVERSE_QUADRATIC 0.5).
struct MistSettings {
  float start = 5.0f, depth = 25.0f, falloff = 2.0f;
};

// What a render is asked to write beside Combined. Pass indices are per instance (Blender's
// object pass_index) and per material id (material pass_index); a missing entry reads 0.
struct AovRequest {
  uint32_t mask = 0;  // bit (1 << Aov) per pass asked for
  MistSettings mist;
  std::vector<float> object_index, material_index;
  CryptomatteRequest cryptomatte;
  bool any() const { return mask != 0 || cryptomatte.any(); }
  bool has(Aov aov) const { return (mask >> uint32_t(aov)) & 1u; }
};

// What the integrator reports of a camera ray's first surface: filled only when asked (a
// non-null pointer), at the first hit, so the lighting code is untouched by passes. `emission`
// and `environment` are filled on a miss too (found false): the lamps and the world it sees.
struct FirstHit {
  bool found = false;
  Vec3 p{0.0f}, normal{0.0f};  // world position; unit shading normal facing the ray
  Vec3 diffuse{0.0f};          // the diffuse albedo (0 for a specular surface)
  Vec3 glossy{0.0f};           // the glossy lobe's albedo (render/glossy_color.h)
  Vec3 emission{0.0f};         // radiance the surface and the lamps in front of it emit
  Vec3 environment{0.0f};      // the world's radiance, when the ray hits nothing
  ShadingPoint at;             // the hit as its material saw it (render/glossy_color.h reads it)
  int32_t instance = -1, material = -1;
};

// The passes of one render: one flat float array per pass asked for (width * height * channels,
// rows from the top, as the Combined image); empty for the others.
struct AovBuffers {
  int width = 0, height = 0;
  std::array<std::vector<float>, kAovCount> data;
  // Per Cryptomatte kind asked for: width * height * cryptomatte.channels() floats, the pixel's
  // (id, coverage) pairs in rank order.
  std::array<std::vector<float>, kCryptoKindCount> cryptomatte;
  void allocate(const AovRequest& request, int w, int h);
};

// One pixel's sums over its samples, on the worker's stack; store() writes the pass values.
class AovPixel {
 public:
  AovPixel(const AovRequest& request, const Camera& camera) : request_(request), camera_(camera) {}
  // `first_sample`: the render's first sample of this pixel, which alone sets depth, position, indices.
  void add(const FirstHit& hit, bool first_sample);
  void store(AovBuffers& buffers, size_t pixel_index, float inv_samples) const;

 private:
  const AovRequest& request_;
  const Camera& camera_;
  float depth_ = 1e10f, object_ = 0.0f, material_ = 0.0f, mist_sum_ = 0.0f;
  Vec3 position_{0.0f}, normal_sum_{0.0f}, diffuse_sum_{0.0f}, glossy_sum_{0.0f}, emission_sum_{0.0f};
  Vec3 environment_sum_{0.0f};
};

}  // namespace toyrt
