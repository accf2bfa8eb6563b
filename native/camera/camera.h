// Blender's camera: primary rays from Blender's camera and render settings, in Blender's units
// and conventions (the view plane of BKE_camera_params_compute_viewplane, which Cycles' sync
// reproduces). Perspective and orthographic; sensor fit, shift, clipping, resolution percentage,
// pixel aspect, the render border, and depth of field (a thin lens: camera/thin_lens.h).
//
// Pixel coordinates: continuous (px, py) with px in [0, width) from the left and py in
// [0, height) from the TOP row, the order images are stored in memory here; pixel (i, j) covers
// [i, i + 1) x [j, j + 1), so its centre is (i + 0.5, j + 0.5). render() returns rows in this
// order too; Blender's RenderResult (and Image.pixels) store rows bottom-up, so the add-on flips
// them (addon/render_toyrt/engine.py and viewport.py, pixels[::-1]) when it hands them over.
#pragma once

#include "camera/thin_lens.h"
#include "core/math.h"
#include "core/ray.h"

namespace toyrt {

enum class CameraType { Perspective, Orthographic };
// Blender's sensor fit: AUTO fits the larger image dimension (after pixel aspect) to
// sensor_width; HORIZONTAL fits the width to sensor_width; VERTICAL fits the height to
// sensor_height. The fitted dimension also sets the unit of shift and of ortho_scale.
enum class SensorFit { Auto, Horizontal, Vertical };

// Blender's settings under Blender's names (bpy.types.Camera and RenderSettings), with Blender's
// defaults. Lengths in mm for the lens and sensor, metres for clipping and ortho_scale.
struct CameraParams {
  CameraType type = CameraType::Perspective;
  float lens = 50.0f;           // focal length, mm (perspective)
  float sensor_width = 36.0f;   // mm
  float sensor_height = 24.0f;  // mm (used by VERTICAL fit only)
  SensorFit sensor_fit = SensorFit::Auto;
  float shift_x = 0.0f, shift_y = 0.0f;        // fractions of the fitted (AUTO: larger) image dimension
  float clip_start = 0.1f, clip_end = 100.0f;  // distances along the view axis, m
  float ortho_scale = 6.0f;                    // extent of the fitted dimension, m (orthographic)
  int resolution_x = 1920, resolution_y = 1080, resolution_percentage = 100;
  float pixel_aspect_x = 1.0f, pixel_aspect_y = 1.0f;
  bool use_border = false;  // render only the border region (Blender's border_min/max, y from the bottom)
  float border_min_x = 0.0f, border_min_y = 0.0f, border_max_x = 1.0f, border_max_y = 1.0f;
  Mat4 matrix_world = Mat4(1.0f);  // the camera object's world matrix; it looks down local -Z, +Y up
  // Depth of field, Blender's camera.dof (the add-on turns a focus object into focus_distance).
  bool use_dof = false;
  float focus_distance = 10.0f;    // m, along the view axis; 0 is clamped to 1e-5 m as Cycles does
  float aperture_fstop = 2.8f;     // radius = lens / (2 fstop) (orthographic: 1 m / (2 fstop)); 0 as 1e-5
  int aperture_blades = 0;         // below 3: a round aperture
  float aperture_rotation = 0.0f;  // radians
  float aperture_ratio = 1.0f;     // anamorphic: the aperture's x is divided by it
};

// A rectangle of pixels [x0, x1) x [y0, y1), rows counted from the top.
struct PixelWindow {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
};

struct Camera {
  CameraType type = CameraType::Perspective;
  int width = 0, height = 0;  // the full image: resolution * percentage / 100 (integer, as Blender)
  PixelWindow window;         // pixels to render: the border, or the whole image
  Vec3 position{0.0f};        // the camera's world position
  Vec3 axis_x{1, 0, 0}, axis_y{0, 1, 0}, axis_z{0, 0, 1};  // unit world axes; the view is along -axis_z
  // The view plane: image left/bottom and right/top edges in camera space, on the plane z = -1
  // for perspective (tangents), in metres for orthographic. Shift is already applied.
  glm::vec2 plane_min{-1.0f}, plane_max{1.0f};
  float clip_start = 0.1f, clip_end = 100.0f;
  ThinLens lens;  // a pinhole unless use_dof and a positive aperture

  // Checks the settings (throws std::invalid_argument naming the bad one) and precomputes the
  // view plane. The matrix's scale is ignored, as Cycles does: only rotation and position count.
  static Camera make(const CameraParams& params);

  // The ray through continuous pixel position (px, py) of the full image (see above), with a
  // unit direction. Clipping is by planes, as in Blender: perspective rays start at the camera
  // with tnear = clip_start / cos(angle to the view axis) and tfar = clip_end / cos(...);
  // orthographic rays start on the near plane (tnear = 0) and end on the far one
  // (tfar = clip_end - clip_start).
  Ray generate(float px, float py) const;
  // The same through the point of the aperture that lens_u in [0, 1)^2 picks (ThinLens::sample):
  // the ray crosses the plane of focus where generate(px, py) does. Clipping stays by planes,
  // measured from the lens plane along this ray. A pinhole lens gives generate(px, py).
  Ray generate(float px, float py, const Vec2& lens_u) const;
};

}  // namespace toyrt
