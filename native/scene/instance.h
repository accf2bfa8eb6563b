// One placement of a mesh in the world: the mesh is shared, the instance carries only its
// transforms (10,000 instances of one mesh cost 10,000 of these, not 10,000 meshes).
#pragma once

#include "core/bbox.h"
#include "lights/light_linking.h"

#include <cstdint>

namespace toyrt {

// Blender's Object ray visibility (visible_camera, visible_diffuse, visible_glossy,
// visible_transmission) as bits: the kinds of path ray that see an instance. Shadow rays have
// Instance::visible_shadow.
enum RayVisibility : uint8_t {
  kVisibleCamera = 1,
  kVisibleDiffuse = 2,
  kVisibleGlossy = 4,
  kVisibleTransmission = 8,
  kVisibleAll = 15,
};

struct Instance {
  uint32_t mesh = 0;
  Mat4 to_world{1.0f};   // object -> world, affine
  Mat4 to_object{1.0f};  // its inverse: rays are carried into object space, t is unchanged
  bool identity = true;  // skips the ray transform for the common untransformed case
  BBox world_bounds;     // of the mesh's box corners, transformed
  // Blender's Object.visible_shadow: whether the instance blocks the render's shadow rays
  // (Scene::shadowed). Camera, glossy and glass rays and the ray API's queries see it regardless.
  bool visible_shadow = true;
  // Light linking (lights/light_linking.h): the receiver set whose lights light it and the blocker
  // set whose lights it shadows; 0 for an object no light's collection names.
  uint8_t receiver_set = 0;
  uint8_t blocker_set = 0;
  // The path rays that see it (RayVisibility bits); the ray API's queries see it regardless. An
  // emissive instance hidden from diffuse rays lights no diffuse surface, as Cycles' mesh lights.
  uint8_t visibility = kVisibleAll;
  // As an emitter (its materials emit): the receiver sets it lights (light linking of an
  // emissive object, Blender 4.0+); all by default.
  uint64_t light_receivers = kAllLightSets;
};

}  // namespace toyrt
