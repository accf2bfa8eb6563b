// The lamps a camera or specular ray sees on its way (lights are not surfaces: Cycles' rays pass
// them). Inline, in a header of its own: the integrator calls it for every ray of a scene with
// lamps, and it was inlined there when it lived in integrator.cpp.
#pragma once

#include "core/math.h"
#include "lights/light_linking.h"
#include "render/glossy_lighting.h"  // power_heuristic
#include "scene/world.h"

#include <cstddef>
#include <limits>

namespace toyrt {

// The radiance of the lights a camera (depth 0) or specular ray passes before distance `limit`
// (in units of the unit direction), of those visible to that kind of ray. Lights are not
// surfaces: as in Cycles, a ray that sees one goes on, so what is behind a light (another light,
// a surface, the world) adds to it. A light at infinity (a sun, at FLT_MAX) is part of the world:
// seen by a ray that leaves the scene (`escaped`), whatever the camera's clip end. bsdf_pdf > 0:
// the ray was drawn by a glossy lobe with that density, and each lamp takes its power-heuristic
// weight against the lamp sample glossy_direct_lighting took there. receiver: the light-linking
// receiver set of the surface the ray left, as Cycles links a lamp a reflection finds to the
// reflecting object; a camera ray has no object and, as in Cycles, counts as set 0 (so a lamp
// that lights only included objects is not seen by the camera either).
inline Vec3 visible_lights(const World& world, const Vec3& org, const Vec3& unit_dir, float from, float limit,
                           bool escaped, bool camera, AreaSampling area_sampling, float bsdf_pdf, uint8_t receiver) {
  constexpr float kAtInfinity = std::numeric_limits<float>::max();
  Vec3 radiance(0.0f);
  for (size_t j = 0; j < world.lights.size(); ++j) {
    const LightVisibility v = world.light_visibility[j];
    if (!(camera ? v.camera : v.specular)) continue;
    if (!in_light_sets(v.receiver_sets, receiver)) continue;
    const LightEval e = evaluate_light(world.lights[j], org, unit_dir, area_sampling);
    if (!e.hit()) continue;
    if (!(e.distance == kAtInfinity ? escaped : (e.distance >= from && e.distance < limit))) continue;
    radiance += bsdf_pdf > 0.0f ? e.radiance * power_heuristic(bsdf_pdf, e.pdf) : e.radiance;
  }
  return radiance;
}

}  // namespace toyrt
