// What lights the scene besides its surfaces: the lights with their ray visibility, and the
// world (a constant background, or an environment map). Plain data held by Scene; the integrator reads it.
#pragma once

#include "lights/light.h"
#include "lights/light_linking.h"
#include "scene/environment.h"
#include "scene/instance.h"

#include <cstdint>
#include <vector>

namespace toyrt {

// Per light, Blender's settings of the light object (all on by default, as in Cycles): whether
// camera rays, reflected (glossy) rays and refracted (transmission) rays see the light itself
// (point and spot lights of radius 0 and suns of angle 0 can never be seen), and whether glossy and
// transmission lobes are lit by it (Cycles excludes a light from the closures of the kinds it is
// hidden from, for its sample as for its image); whether it lights diffuse surfaces at all (the
// object's diffuse ray visibility); whether surfaces between it and a point shadow it (Cycles 3.x
// light.cycles.cast_shadow, 4.x+ light.use_shadow).
// Light linking (lights/light_linking.h): the receiver sets the light lights and the blocker sets
// that shadow it; full masks (the default) link nothing.
struct LightVisibility {
  bool camera = true;
  bool glossy = true;
  bool transmission = true;
  bool diffuse = true;
  bool shadow = true;
  uint64_t receiver_sets = kAllLightSets;
  uint64_t blocker_sets = kAllLightSets;

  // Whether a path ray of kind `ray` (one RayVisibility bit of scene/instance.h) sees the light.
  bool seen_by(uint8_t ray) const {
    return ray == kVisibleCamera    ? camera
           : ray == kVisibleGlossy  ? glossy
           : ray == kVisibleDiffuse ? diffuse
                                    : ray == kVisibleTransmission && transmission;
  }
};

struct World {
  std::vector<Light> lights;
  std::vector<LightVisibility> light_visibility;  // parallel to lights
  Vec3 background{0.0f};    // radiance of rays that leave the scene (the world colour), linear RGB
  Environment environment;  // when active, the radiance of rays that leave the scene instead
  // Whether the background also lights diffuse surfaces (Cycles samples the world as a light;
  // Blender's world ray visibility for diffuse rays turns it off).
  bool background_lights_surfaces = true;
  // Whether rays that leave the scene see it, by the kind of their last vertex (Blender's world
  // ray visibility, world.cycles_visibility.camera / .glossy / .transmission): off, they see
  // black, still opaque, as in Cycles (transparency is the film's setting). As Cycles' path
  // flags: a ray reflected by a glossy or mirror surface is a glossy ray, one refracted through
  // glass a transmission ray; a ray that passed a cut-out keeps the kind it had.
  bool background_visible_camera = true;
  bool background_visible_glossy = true;
  bool background_visible_transmission = true;
};

// The kind of a ray a path traces, for the world's visibility above.
// Diffuse: a ray a diffuse closure drew where Cycles' closures are mixed (materials/closure_mixture.h),
// which only looks for light.
enum class RayKind : uint8_t { Camera, Glossy, Transmission, Diffuse };

inline bool background_visible(const World& world, RayKind kind) {
  switch (kind) {
    case RayKind::Camera:
      return world.background_visible_camera;
    case RayKind::Glossy:
      return world.background_visible_glossy;
    case RayKind::Transmission:
      return world.background_visible_transmission;
    case RayKind::Diffuse:
      return world.background_lights_surfaces;
  }
  return true;
}

}  // namespace toyrt
