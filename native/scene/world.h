// What lights the scene besides its surfaces: the lights with their ray visibility, and the
// world (a constant background). Plain data held by Scene; the integrator reads it.
#pragma once

#include "lights/light.h"

#include <vector>

namespace toyrt {

// Per light: whether camera rays, and rays continuing through refraction or reflection, see the
// light itself (Blender's ray visibility of the light object; Cycles shows lights to both by
// default). Point lights of radius 0 can never be seen.
struct LightVisibility {
  bool camera = true;
  bool specular = true;
};

struct World {
  std::vector<Light> lights;
  std::vector<LightVisibility> light_visibility;  // parallel to lights
  Vec3 background{0.0f};  // radiance of rays that leave the scene (the world colour), linear RGB
  // Whether the background also lights diffuse surfaces (Cycles samples the world as a light;
  // Blender's world ray visibility for diffuse rays turns it off).
  bool background_lights_surfaces = true;
};

}  // namespace toyrt
