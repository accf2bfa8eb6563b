// The view plane follows Blender's BKE_camera_params_compute_viewplane: the fitted dimension
// spans sensor_size / lens at unit distance (ortho_scale in metres for orthographic), the other
// dimension follows from the image's aspect ratio including pixel aspect, and shift is a
// fraction of the fitted dimension.
#include "camera/camera.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace toyrt {
namespace {

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument("camera: " + message);
}

bool finite_positive(float v) { return std::isfinite(v) && v > 0.0f; }

}  // namespace

Camera Camera::make(const CameraParams& p) {
  require(p.resolution_x > 0 && p.resolution_y > 0, "resolution_x and resolution_y must be positive");
  require(p.resolution_percentage > 0, "resolution_percentage must be positive");
  require(finite_positive(p.pixel_aspect_x) && finite_positive(p.pixel_aspect_y),
          "pixel_aspect_x and pixel_aspect_y must be positive and finite");
  if (p.type == CameraType::Perspective) {
    require(finite_positive(p.lens), "lens (focal length, mm) must be positive and finite");
    require(p.sensor_fit == SensorFit::Vertical ? finite_positive(p.sensor_height) : finite_positive(p.sensor_width),
            "the fitted sensor size (mm) must be positive and finite");
  } else {
    require(finite_positive(p.ortho_scale), "ortho_scale must be positive and finite");
  }
  require(std::isfinite(p.shift_x) && std::isfinite(p.shift_y), "shift_x and shift_y must be finite");
  require(std::isfinite(p.clip_start) && std::isfinite(p.clip_end) && p.clip_start >= 0.0f && p.clip_end > p.clip_start,
          "clipping needs 0 <= clip_start < clip_end, both finite");
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) require(std::isfinite(p.matrix_world[c][r]), "matrix_world is not finite");
  require(p.matrix_world[0][3] == 0.0f && p.matrix_world[1][3] == 0.0f && p.matrix_world[2][3] == 0.0f &&
              p.matrix_world[3][3] == 1.0f,
          "matrix_world must be affine: its last row must be 0 0 0 1");

  if (p.use_dof) {
    require(std::isfinite(p.focus_distance) && p.focus_distance >= 0.0f,
            "focus_distance must be finite and not negative");
    require(std::isfinite(p.aperture_fstop) && p.aperture_fstop >= 0.0f,
            "aperture_fstop must be finite and not negative");
    require(p.aperture_blades >= 0, "aperture_blades must not be negative");
    require(std::isfinite(p.aperture_rotation), "aperture_rotation must be finite");
    require(finite_positive(p.aperture_ratio), "aperture_ratio must be positive and finite");
  }

  Camera cam;
  cam.type = p.type;
  // Blender's BKE_render_resolution: integer arithmetic, truncating.
  const long long w = (long long)p.resolution_x * p.resolution_percentage / 100;
  const long long h = (long long)p.resolution_y * p.resolution_percentage / 100;
  require(w >= 1 && h >= 1 && w <= (1 << 24) && h <= (1 << 24),
          "the render size (resolution * percentage / 100) must be 1 to 2^24 pixels per side");
  cam.width = int(w);
  cam.height = int(h);

  // Scale is dropped (Cycles normalises the camera matrix's axes); a zero axis cannot be.
  const Vec3 cx(p.matrix_world[0]), cy(p.matrix_world[1]), cz(p.matrix_world[2]);
  require(glm::length(cx) > 0.0f && glm::length(cy) > 0.0f && glm::length(cz) > 0.0f,
          "matrix_world has a zero axis (zero scale)");
  cam.axis_x = glm::normalize(cx);
  cam.axis_y = glm::normalize(cy);
  cam.axis_z = glm::normalize(cz);
  cam.position = Vec3(p.matrix_world[3]);

  // Sensor fit, in double: the aspect ratios of large images are exact there.
  const double x_ratio = double(cam.width) * p.pixel_aspect_x;
  const double y_ratio = double(cam.height) * p.pixel_aspect_y;
  const bool horizontal =
      p.sensor_fit == SensorFit::Horizontal || (p.sensor_fit == SensorFit::Auto && x_ratio >= y_ratio);
  const double sensor = p.sensor_fit == SensorFit::Vertical ? p.sensor_height : p.sensor_width;
  // Extent of the fitted dimension: on the plane at unit distance, or in metres.
  const double size = p.type == CameraType::Perspective ? sensor / p.lens : double(p.ortho_scale);
  const double half_x = horizontal ? 0.5 * size : 0.5 * size * x_ratio / y_ratio;
  const double half_y = horizontal ? 0.5 * size * y_ratio / x_ratio : 0.5 * size;
  const double centre_x = p.shift_x * size, centre_y = p.shift_y * size;
  cam.plane_min = glm::vec2(float(centre_x - half_x), float(centre_y - half_y));
  cam.plane_max = glm::vec2(float(centre_x + half_x), float(centre_y + half_y));
  cam.clip_start = p.clip_start;
  cam.clip_end = p.clip_end;

  if (p.use_dof) {
    // Cycles' rules (blender/camera.cpp, scene/camera.cpp): the lens in mm over twice the f-stop,
    // in metres; an orthographic camera has no focal length, so 1 m stands in for it. A zero
    // f-stop or focus distance is clamped to 1e-5, never refused, as Blender allows both.
    const float fstop = std::max(p.aperture_fstop, 1e-5f);
    cam.lens.radius = (p.type == CameraType::Perspective ? p.lens * 1e-3f : 1.0f) / (2.0f * fstop);
    cam.lens.focus_distance = std::max(p.focus_distance, 1e-5f);
    cam.lens.blades = p.aperture_blades < 3 ? 0 : p.aperture_blades;
    cam.lens.rotation = p.aperture_rotation;
    cam.lens.inv_ratio = 1.0f / p.aperture_ratio;
  }

  cam.window = {0, 0, cam.width, cam.height};
  if (p.use_border) {
    require(std::isfinite(p.border_min_x) && std::isfinite(p.border_max_x) && std::isfinite(p.border_min_y) &&
                std::isfinite(p.border_max_y) && 0.0f <= p.border_min_x && p.border_min_x < p.border_max_x &&
                p.border_max_x <= 1.0f && 0.0f <= p.border_min_y && p.border_min_y < p.border_max_y &&
                p.border_max_y <= 1.0f,
            "the border needs 0 <= min < max <= 1 on both axes");
    // Blender's render pipeline truncates border * size to whole pixels; its y runs from the
    // bottom, our rows from the top.
    const int x0 = int(p.border_min_x * cam.width), x1 = int(p.border_max_x * cam.width);
    const int bottom0 = int(p.border_min_y * cam.height), bottom1 = int(p.border_max_y * cam.height);
    cam.window = {x0, cam.height - bottom1, x1, cam.height - bottom0};
    require(cam.window.width() >= 1 && cam.window.height() >= 1, "the border selects no pixel");
  }
  return cam;
}

Ray Camera::generate(float px, float py) const {
  const float sx = plane_min.x + (px / float(width)) * (plane_max.x - plane_min.x);
  const float sy = plane_max.y - (py / float(height)) * (plane_max.y - plane_min.y);
  Ray ray;
  if (type == CameraType::Perspective) {
    // Camera-space direction (sx, sy, -1): its length is 1 / cos(angle to the axis), which turns
    // the clip planes' depths into distances along the unit direction.
    const float length = std::sqrt(sx * sx + sy * sy + 1.0f);
    ray.org = position;
    ray.dir = (sx * axis_x + sy * axis_y - axis_z) / length;
    ray.tnear = clip_start * length;
    ray.tfar = clip_end * length;
  } else {
    ray.org = position + sx * axis_x + sy * axis_y - clip_start * axis_z;
    ray.dir = -axis_z;
    ray.tnear = 0.0f;
    ray.tfar = clip_end - clip_start;
  }
  return ray;
}

Ray Camera::generate(float px, float py, const Vec2& lens_u) const {
  if (lens.pinhole()) return generate(px, py);
  const float sx = plane_min.x + (px / float(width)) * (plane_max.x - plane_min.x);
  const float sy = plane_max.y - (py / float(height)) * (plane_max.y - plane_min.y);
  const Vec2 a = lens.sample(lens_u);
  // Camera space, the view along -z. The pinhole ray through (sx, sy) reaches depth f at
  // (sx f, sy f) (perspective) or (sx, sy) (orthographic, from the plane point (sx, sy, 0)).
  const float f = lens.focus_distance;
  const bool perspective = type == CameraType::Perspective;
  const Vec3 start = perspective ? Vec3(a.x, a.y, 0.0f) : Vec3(sx + a.x, sy + a.y, 0.0f);
  const Vec3 focus = perspective ? Vec3(sx * f, sy * f, -f) : Vec3(sx, sy, -f);
  const Vec3 d = glm::normalize(focus - start);
  // 1 / cos(angle to the view axis) turns the clip planes' depths into distances along d.
  const float per_depth = 1.0f / -d.z;
  Ray ray;
  ray.dir = d.x * axis_x + d.y * axis_y + d.z * axis_z;
  const Vec3 org = position + start.x * axis_x + start.y * axis_y;
  if (perspective) {
    ray.org = org;
    ray.tnear = clip_start * per_depth;
    ray.tfar = clip_end * per_depth;
  } else {
    // As the pinhole orthographic ray, it starts on the near plane.
    ray.org = org + (clip_start * per_depth) * ray.dir;
    ray.tnear = 0.0f;
    ray.tfar = (clip_end - clip_start) * per_depth;
  }
  return ray;
}

}  // namespace toyrt
