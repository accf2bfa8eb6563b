// Direct lighting with specular chains, the seed report's light transport in Blender's units:
// at a diffuse hit, light samples with shadow rays (the any-hit query); at a refractive hit, the
// path continues along the refracted or reflected direction; a ray that leaves the scene sees the
// background. This matches Cycles with max bounces 0 (transmission bounces only for glass).
#pragma once

#include "render/aovs.h"
#include "render/render_settings.h"
#include "scene/scene.h"

namespace toyrt {

// Radiance along the camera ray for sample `sample` of pixel `pixel` (which, with the seed, picks
// every random number: results do not depend on thread or tile order). Non-negative and finite.
// Reads the committed scene in place. settings.light_sampling must be resolved (All or One:
// resolve_light_sampling); Auto is treated as All. `first`, when not null, receives what the
// camera ray's first surface is (render passes, aovs.h); null costs one untaken branch per hit.
Vec3 trace_path(const Scene& scene, const Ray& camera_ray, uint32_t pixel, uint32_t sample,
                const IntegratorSettings& settings, FirstHit* first = nullptr);

}  // namespace toyrt
