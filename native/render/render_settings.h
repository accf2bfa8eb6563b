// The settings of one render, with their defaults: the one place they are written down (the
// Python binding reads its argument defaults and toyrt.defaults from these structs, and the
// add-on's properties are tested equal to them). check() holds the bounds; the names parse the
// strings users pass.
#pragma once

#include "camera/ray_cone.h"
#include "lights/area_light.h"
#include "render/adaptive_sampling.h"

#include <cstddef>
#include <cstdint>
#include <string>

namespace toyrt {

enum class LightSampling {
  Auto,  // All up to kAllLightsUpTo lights, One beyond
  All,   // one sample of every light at every diffuse hit
  One,   // one light per hit, chosen by its expected contribution (LightSelector)
};
// "auto" samples every light at every hit up to this many lights: each costs a shadow ray, and
// beyond a few the selector's one ray per hit wins.
inline constexpr size_t kAllLightsUpTo = 4;

// "auto", "all", "one"; throws std::invalid_argument on anything else.
LightSampling parse_light_sampling(const std::string& name);
const char* light_sampling_name(LightSampling sampling);
// Auto resolved for a scene of `light_count` lights (All and One stay).
LightSampling resolve_light_sampling(LightSampling sampling, size_t light_count);

struct IntegratorSettings {
  int max_specular_depth = 8;  // refraction / reflection events before a path is cut
  LightSampling light_sampling = LightSampling::Auto;
  // How rectangular area lights are sampled (disks and ellipses always by area).
  AreaSampling area_sampling = AreaSampling::SolidAngle;
  uint32_t seed = 0;
  // Fresnel (glass) vertices before this depth trace both reflection and refraction, weighted by
  // F and 1 - F; deeper ones pick one branch with those probabilities. 0 turns splitting off.
  // Costs extra rays only in pixels that see glass; see docs/render.md for the measured gain.
  int split_depth = 2;
  // Transparent surfaces (materials/transparency.h) a path or a shadow ray may pass, Cycles'
  // transparent_max_bounces: a path that crossed this many shades nothing at its next surface (it
  // sees that surface's emission and the world beyond), and a shadow ray that meets more than
  // what remains of it along its path is blocked. >= 0. Within one path the integrator lowers it
  // by each crossing, so shadow rays read what remains.
  int transparent_max_bounces = 8;
  // Not a user setting: render() points it at its camera's constants for Cycles 3.x's ray
  // footprints (camera/ray_cone.h), read only by bump maps that difference over a footprint.
  // Null: zero footprints (those bumps take the slope at the point).
  const CameraCone* camera_cone = nullptr;
};

struct RenderSettings {
  int samples = 16;  // per pixel, on a Sobol-Owen pattern, box filter of one pixel
  // The first sample index: a pass renders samples [first_sample, first_sample + samples) of the
  // same sequence, so passes of n1 and n2 samples averaged with weights n1 and n2 equal one
  // render of n1 + n2 samples (the viewport accumulates this way).
  int first_sample = 0;
  int tile_size = 32;  // pixels
  int threads = 0;     // 0: all cores
  IntegratorSettings integrator;
  AdaptiveSettings adaptive;  // per-pixel stopping (render/adaptive_sampling.h)
  // Seconds of rendering after which no further pass starts (Cycles' time_limit: the scene's
  // export and BVH build are not counted); 0: none. With a limit the image is rendered in passes
  // over the whole window (1, 1, 2, 4... samples), each sized to end before the limit, so the
  // image is always a complete render of every sample taken.
  double time_limit = 0.0;

  // Throws std::invalid_argument naming the first setting out of its bounds.
  void check() const;
};

}  // namespace toyrt
