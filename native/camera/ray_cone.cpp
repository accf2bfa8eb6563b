#include "camera/ray_cone.h"

#include "camera/camera.h"

namespace toyrt {

CameraCone CameraCone::of(const Camera& camera) {
  CameraCone c;
  c.perspective = camera.type == CameraType::Perspective;
  c.axis_x = camera.axis_x;
  c.axis_y = camera.axis_y;
  c.axis_z = camera.axis_z;
  c.step_x = (camera.plane_max.x - camera.plane_min.x) / float(camera.width);
  c.step_y = (camera.plane_max.y - camera.plane_min.y) / float(camera.height);
  return c;
}

RayCone CameraCone::of_ray(const Vec3& dir) const {
  if (!perspective) return RayCone{step_x, 0.0f};
  // The direction on the view plane at unit depth, (x, y, -1) in camera space.
  const float depth = -glm::dot(dir, axis_z);
  if (!(depth > 0.0f)) return RayCone{};
  const Vec3 q(glm::dot(dir, axis_x) / depth, glm::dot(dir, axis_y) / depth, -1.0f);
  const Vec3 d = glm::normalize(q);
  const float dx = glm::length(glm::normalize(q + Vec3(step_x, 0.0f, 0.0f)) - d);
  const float dy = glm::length(glm::normalize(q + Vec3(0.0f, step_y, 0.0f)) - d);
  return RayCone{0.0f, 0.5f * (dx + dy)};
}

}  // namespace toyrt
