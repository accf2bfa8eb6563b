// The small scenes the render tests check closed forms on: a 20 m floor at z = 0 of one material,
// seen through one pixel of an orthographic camera 5 m above it looking down.
#pragma once

#include "materials/material.h"
#include "render/renderer.h"
#include "scene/scene.h"

#include <glm/gtc/matrix_transform.hpp>

namespace toyrt::testing {

inline Scene floor_of(const Material& material) {
  Scene scene;
  const float h = 10.0f;
  MeshShading sh;
  sh.material_ids = {0, 0};
  scene.add_instance(scene.add_mesh({{-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}}, {{0, 1, 2}, {0, 2, 3}}, sh),
                     Mat4(1.0f));
  scene.add_material(material);
  return scene;
}

// One pixel of an orthographic camera 5 m above the origin looking down, `size` m wide.
inline Camera pixel_above(float size = 1e-3f) {
  CameraParams p;
  p.type = CameraType::Orthographic;
  p.ortho_scale = size;
  p.resolution_x = p.resolution_y = 1;
  p.matrix_world = glm::translate(Mat4(1.0f), Vec3(0.0f, 0.0f, 5.0f));
  return Camera::make(p);
}

// `samples` per pixel on one thread (the result does not depend on the thread count).
inline RenderSettings few_samples(int samples) {
  RenderSettings s;
  s.samples = samples;
  s.threads = 1;
  return s;
}

}  // namespace toyrt::testing
