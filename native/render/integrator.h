// Direct lighting with specular chains, the seed report's light transport in Blender's units:
// at a diffuse hit, light samples with shadow rays (the any-hit query); at a refractive hit, the
// path continues along the refracted or reflected direction; a ray that leaves the scene sees the
// background. This matches Cycles with max bounces 0 (transmission bounces only for glass).
#pragma once

#include "render/render_scene.h"

namespace toyrt {

enum class LightSampling {
  All,  // one sample of every light at every diffuse hit
  One,  // one light per hit, chosen by its expected contribution (LightSelector)
};

struct IntegratorSettings {
  int max_specular_depth = 8;  // refraction / reflection events before a path is cut
  LightSampling light_sampling = LightSampling::All;
  uint32_t seed = 0;
  // Fresnel (glass) vertices before this depth trace both reflection and refraction, weighted by
  // F and 1 - F; deeper ones pick one branch with those probabilities. 0 turns splitting off.
  // Costs extra rays only in pixels that see glass; see docs/render.md for the measured gain.
  int split_depth = 2;
};

// Radiance along the camera ray for sample `sample` of pixel `pixel` (which, with the seed, picks
// every random number: results do not depend on thread or tile order). Non-negative and finite.
Vec3 trace_path(const RenderScene& scene, const Ray& camera_ray, uint32_t pixel, uint32_t sample,
                const IntegratorSettings& settings);

}  // namespace toyrt
