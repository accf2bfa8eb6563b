// What lights the scene besides its surfaces: the lights with their ray visibility, and the
// world (a constant background, or an environment map). Plain data held by Scene; the integrator reads it.
#pragma once

#include "lights/light.h"
#include "scene/environment.h"

#include <vector>

namespace toyrt {

// Per light, Blender's settings of the light object (all on by default, as in Cycles): whether
// camera rays, and rays continuing through refraction or reflection, see the light itself (point
// and spot lights of radius 0 and suns of angle 0 can never be seen); whether it lights diffuse
// surfaces at all (the object's diffuse ray visibility); whether surfaces between it and a
// point shadow it (Cycles 3.x light.cycles.cast_shadow, 4.x+ light.use_shadow).
struct LightVisibility {
  bool camera = true;
  bool specular = true;
  bool diffuse = true;
  bool shadow = true;
};

struct World {
  std::vector<Light> lights;
  std::vector<LightVisibility> light_visibility;  // parallel to lights
  Vec3 background{0.0f};    // radiance of rays that leave the scene (the world colour), linear RGB
  Environment environment;  // when active, the radiance of rays that leave the scene instead
  // Whether the background also lights diffuse surfaces (Cycles samples the world as a light;
  // Blender's world ray visibility for diffuse rays turns it off).
  bool background_lights_surfaces = true;
  // Whether camera rays that leave the scene see it (Blender's world ray visibility for camera
  // rays, world.cycles_visibility.camera): off, they see black, still opaque, as in Cycles
  // (transparency is the film's setting). Rays through glass and off glossy surfaces see it.
  bool background_visible_camera = true;
};

}  // namespace toyrt
