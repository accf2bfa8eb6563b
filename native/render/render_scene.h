// Everything the integrator reads besides the geometry: per-mesh shading attributes, materials,
// textures, lights, background. Plain data filled by the Python binding (or tests); the
// geometry itself (meshes, instances, BVHs) stays in Scene, shared with the ray API.
#pragma once

#include "lights/light.h"
#include "materials/material.h"
#include "materials/texture.h"
#include "scene/scene.h"

#include <vector>

namespace toyrt {

// Shading attributes of one mesh, by triangle corner (Blender's loop triangles): each array is
// empty when the mesh does not have it. Flat shading uses the geometric normal.
struct MeshShading {
  std::vector<Vec3> corner_normals;   // 3 per triangle, object space (smooth or custom normals)
  std::vector<Vec2> corner_uvs;       // 3 per triangle
  std::vector<int32_t> material_ids;  // 1 per triangle, into RenderScene::materials
};

struct RenderScene {
  const Scene* geometry = nullptr;     // committed before rendering
  std::vector<MeshShading> shading;    // by mesh id (may be shorter: missing means no attributes)
  std::vector<Material> materials;     // empty: every surface is Lambert with albedo 0.8
  std::vector<Texture> textures;
  std::vector<Light> lights;
  // Per light: whether camera rays, and rays continuing through refraction or reflection, see
  // the light itself (Blender's ray visibility of the light object; Cycles shows lights to both
  // by default). Point lights of radius 0 can never be seen.
  struct LightVisibility {
    bool camera = true;
    bool specular = true;
  };
  std::vector<LightVisibility> light_visibility;  // parallel to lights
  Vec3 background{0.0f};               // radiance of rays that leave the scene (the world colour)
  // Whether the background also lights diffuse surfaces (Cycles samples the world as a light;
  // Blender's world ray visibility for diffuse rays turns it off).
  bool background_lights_surfaces = true;
};

}  // namespace toyrt
