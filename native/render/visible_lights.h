// The lamps a camera or specular ray sees on its way (lights are not surfaces: Cycles' rays pass
// them). Inline, in a header of its own: the integrator calls it for every ray of a scene with
// lamps, and it was inlined there when it lived in integrator.cpp.
#pragma once

#include "core/math.h"
#include "lights/lamp_bvh.h"
#include "lights/light_linking.h"
#include "lights/light_selector.h"
#include "render/glossy_lighting.h"  // power_heuristic
#include "scene/world.h"

#include <cstddef>
#include <limits>

namespace toyrt {

// How the vertex a ray left sampled the lamps: each of them (selector null), or one picked by
// `selector` at (p, n) (glossy_lighting.h, picks_one_lamp), whose probability a lamp the ray
// finds then multiplies into its pdf.
struct LampChoice {
  const LightSelector* selector = nullptr;
  Vec3 p{0.0f}, n{0.0f};
};

// The radiance of the lights a camera, glossy or transmission ray (`ray`, one RayVisibility bit)
// passes before distance `limit` (in units of the unit direction), of those visible to that kind
// of ray. Lights are not surfaces: as in Cycles, a ray that sees one goes on, so what is behind a
// light (another light, a surface, the world) adds to it. A light at infinity (a sun, at FLT_MAX) is part of the world:
// seen by a ray that leaves the scene (`escaped`), whatever the camera's clip end. bsdf_pdf > 0:
// the ray was drawn by a glossy or rough dielectric lobe with that density, and each lamp takes
// its power-heuristic weight against the lamp sample that vertex took (of the lamp `choice`
// picked). receiver: the light-linking receiver set of the surface the ray left, as Cycles links
// a lamp a reflection finds to the reflecting object; a camera ray has no object and, as in
// Cycles, counts as set 0 (so a lamp that lights only included objects is not seen by the camera
// either). `lamps`: the scene's lamp BVH (lights/lamp_bvh.h), or empty: every lamp is tested.
inline Vec3 visible_lights(const World& world, const LampBvh& lamps, const Vec3& org, const Vec3& unit_dir, float from,
                           float limit, bool escaped, uint8_t ray, AreaSampling area_sampling, float bsdf_pdf,
                           uint8_t receiver, const LampChoice& choice = {}) {
  constexpr float kAtInfinity = std::numeric_limits<float>::max();
  Vec3 radiance(0.0f);
  auto see = [&](size_t j) {
    const LightVisibility v = world.light_visibility[j];
    if (!v.seen_by(ray)) return;
    if (!in_light_sets(v.receiver_sets, receiver)) return;
    const LightEval e = evaluate_light(world.lights[j], org, unit_dir, area_sampling);
    if (!e.hit()) return;
    if (!(e.distance == kAtInfinity ? escaped : (e.distance >= from && e.distance < limit))) return;
    if (!(bsdf_pdf > 0.0f)) {
      radiance += e.radiance;
      return;
    }
    const float pick = choice.selector ? choice.selector->probability(choice.p, choice.n, j, receiver) : 1.0f;
    radiance += e.radiance * power_heuristic(bsdf_pdf, e.pdf * pick);
  };
  if (lamps.empty()) {
    for (size_t j = 0; j < world.lights.size(); ++j) see(j);
  } else {
    for_lamps_along(lamps, org, unit_dir, from, limit, escaped, see);
  }
  return radiance;
}

}  // namespace toyrt
