// Blender's camera against closed forms: the pinhole angles set by lens and sensor fit, shift,
// pixel aspect, orthographic extent, clip planes, the render border, and a round trip through an
// independently written pinhole projection. The ray cones of Cycles 3.x's footprints: a
// perspective ray's spread is the chord of the angle one pixel turns it by, an orthographic ray's
// width one pixel.
#include "camera/camera.h"
#include "camera/ray_cone.h"

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <cstring>
#include <random>
#include <stdexcept>
#include <vector>

using namespace toyrt;

namespace {

float angle_to_axis(const Camera& cam, const Ray& ray) {
  return std::acos(std::min(1.0f, glm::dot(ray.dir, -cam.axis_z)));
}

Mat4 some_camera_matrix() {
  Mat4 m = glm::translate(Mat4(1.0f), Vec3(1.5f, -2.0f, 3.0f));
  m = glm::rotate(m, 0.7f, glm::normalize(Vec3(0.3f, 1.0f, -0.5f)));
  return m;
}

CameraParams landscape() {
  CameraParams p;
  p.resolution_x = 640;
  p.resolution_y = 480;
  p.lens = 35.0f;
  return p;
}

}  // namespace

TEST(Camera, CentrePixelLooksDownMinusZ) {
  CameraParams p = landscape();
  p.matrix_world = some_camera_matrix();
  const Camera cam = Camera::make(p);
  const Ray ray = cam.generate(320.0f, 240.0f);
  const Vec3 minus_z = -glm::normalize(Vec3(p.matrix_world[2]));
  EXPECT_NEAR(glm::length(ray.dir - minus_z), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::length(ray.org - Vec3(p.matrix_world[3])), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::length(ray.dir), 1.0f, 1e-6f);
  // The object's scale does not change the view (Cycles drops it).
  p.matrix_world = glm::scale(p.matrix_world, Vec3(2.0f, 0.5f, 3.0f));
  const Ray scaled = Camera::make(p).generate(17.3f, 400.1f);
  EXPECT_NEAR(glm::length(scaled.dir - cam.generate(17.3f, 400.1f).dir), 0.0f, 1e-6f);
}

TEST(Camera, HorizontalFitEdgeAngleIsAtanHalfSensorOverLens) {
  for (auto [w, h] : {std::pair{640, 480}, std::pair{480, 640}}) {  // holds for portrait too
    CameraParams p = landscape();
    p.resolution_x = w;
    p.resolution_y = h;
    p.sensor_fit = SensorFit::Horizontal;
    const Camera cam = Camera::make(p);
    const float expected = std::atan(p.sensor_width / 2.0f / p.lens);
    EXPECT_NEAR(angle_to_axis(cam, cam.generate(0.0f, h / 2.0f)), expected, 1e-6f);
    EXPECT_NEAR(angle_to_axis(cam, cam.generate(float(w), h / 2.0f)), expected, 1e-6f);
    // The vertical extent follows the aspect ratio.
    EXPECT_NEAR(angle_to_axis(cam, cam.generate(w / 2.0f, 0.0f)),
                std::atan(p.sensor_width / 2.0f / p.lens * float(h) / float(w)), 1e-6f);
  }
}

TEST(Camera, AutoFitOnPortraitFitsVertical) {
  CameraParams p = landscape();
  p.resolution_x = 480;
  p.resolution_y = 640;
  p.sensor_fit = SensorFit::Auto;
  const Camera cam = Camera::make(p);
  // The larger (vertical) dimension spans sensor_width.
  EXPECT_NEAR(angle_to_axis(cam, cam.generate(240.0f, 0.0f)), std::atan(p.sensor_width / 2.0f / p.lens), 1e-6f);
  EXPECT_NEAR(angle_to_axis(cam, cam.generate(0.0f, 320.0f)),
              std::atan(p.sensor_width / 2.0f / p.lens * 480.0f / 640.0f), 1e-6f);
  // The top row looks up (+Y), the left column left (-X).
  EXPECT_GT(glm::dot(cam.generate(240.0f, 0.0f).dir, cam.axis_y), 0.0f);
  EXPECT_LT(glm::dot(cam.generate(0.0f, 320.0f).dir, cam.axis_x), 0.0f);
}

TEST(Camera, VerticalFitUsesSensorHeight) {
  CameraParams p = landscape();
  p.sensor_fit = SensorFit::Vertical;
  p.sensor_height = 20.0f;
  const Camera cam = Camera::make(p);
  EXPECT_NEAR(angle_to_axis(cam, cam.generate(320.0f, 0.0f)), std::atan(10.0f / p.lens), 1e-6f);
  EXPECT_NEAR(angle_to_axis(cam, cam.generate(0.0f, 240.0f)), std::atan(10.0f / p.lens * 640.0f / 480.0f), 1e-6f);
}

TEST(Camera, ShiftMovesImageCentreByShiftTimesLargerDimension) {
  for (auto [w, h] : {std::pair{640, 480}, std::pair{480, 640}}) {
    CameraParams p = landscape();
    p.resolution_x = w;
    p.resolution_y = h;
    const Camera plain = Camera::make(p);
    p.shift_x = 0.1f;
    p.shift_y = -0.25f;
    const Camera shifted = Camera::make(p);
    const float larger = float(std::max(w, h));
    // The shifted image's centre is where the unshifted projection has pixel
    // (centre + shift_x * larger, centre - shift_y * larger): y rows run downwards.
    const Ray a = shifted.generate(w / 2.0f, h / 2.0f);
    const Ray b = plain.generate(w / 2.0f + 0.1f * larger, h / 2.0f + 0.25f * larger);
    EXPECT_NEAR(glm::length(a.dir - b.dir), 0.0f, 1e-6f) << w << "x" << h;
    // Shift translates the image: every pixel moves by the same amount.
    EXPECT_NEAR(
        glm::length(shifted.generate(3.0f, 7.0f).dir - plain.generate(3.0f + 0.1f * larger, 7.0f + 0.25f * larger).dir),
        0.0f, 1e-6f);
  }
}

TEST(Camera, PixelAspectStretches) {
  CameraParams p = landscape();
  p.resolution_x = 400;
  p.resolution_y = 400;
  p.pixel_aspect_x = 1.0f;
  p.pixel_aspect_y = 2.0f;  // pixels twice as tall as wide: the image is 400 x 800 in square units
  const Camera cam = Camera::make(p);
  const float half_tan = p.sensor_width / 2.0f / p.lens;  // AUTO fits the (now larger) height
  EXPECT_NEAR(angle_to_axis(cam, cam.generate(200.0f, 0.0f)), std::atan(half_tan), 1e-6f);
  EXPECT_NEAR(angle_to_axis(cam, cam.generate(0.0f, 200.0f)), std::atan(half_tan / 2.0f), 1e-6f);
  // One pixel step in y covers twice the plane distance of one step in x.
  const Ray c = cam.generate(200.0f, 200.0f), dx = cam.generate(201.0f, 200.0f), dy = cam.generate(200.0f, 201.0f);
  const float step_x = glm::length(dx.dir / glm::dot(dx.dir, -cam.axis_z) - c.dir / glm::dot(c.dir, -cam.axis_z));
  const float step_y = glm::length(dy.dir / glm::dot(dy.dir, -cam.axis_z) - c.dir / glm::dot(c.dir, -cam.axis_z));
  EXPECT_NEAR(step_y / step_x, 2.0f, 1e-3f);
}

TEST(Camera, OrthographicRaysAreParallelAndSpanOrthoScale) {
  for (auto [w, h] : {std::pair{640, 480}, std::pair{480, 640}}) {
    CameraParams p = landscape();
    p.type = CameraType::Orthographic;
    p.ortho_scale = 7.5f;
    p.resolution_x = w;
    p.resolution_y = h;
    p.clip_start = 0.5f;
    p.clip_end = 40.0f;
    p.matrix_world = some_camera_matrix();
    const Camera cam = Camera::make(p);
    const Vec3 view = -glm::normalize(Vec3(p.matrix_world[2]));
    for (Vec3 pix : {Vec3(0, 0, 0), Vec3(w, h, 0), Vec3(13.5f, 200.25f, 0)}) {
      const Ray r = cam.generate(pix.x, pix.y);
      EXPECT_NEAR(glm::length(r.dir - view), 0.0f, 1e-6f);
      // Origins on the near plane, rays ending on the far plane.
      EXPECT_NEAR(glm::dot(r.org - cam.position, view), p.clip_start, 1e-5f);
      EXPECT_NEAR(glm::dot(r.org + r.tfar * r.dir - cam.position, view), p.clip_end, 1e-4f);
      EXPECT_EQ(r.tnear, 0.0f);
    }
    // The larger dimension spans ortho_scale; the other one in proportion.
    const float span_x = glm::length(cam.generate(float(w), h / 2.0f).org - cam.generate(0.0f, h / 2.0f).org);
    const float span_y = glm::length(cam.generate(w / 2.0f, float(h)).org - cam.generate(w / 2.0f, 0.0f).org);
    EXPECT_NEAR(std::max(span_x, span_y), 7.5f, 1e-5f);
    EXPECT_NEAR(std::min(span_x, span_y), 7.5f * 480.0f / 640.0f, 1e-5f);
  }
}

TEST(Camera, ClipPlanesArePlanes) {
  CameraParams p = landscape();
  p.clip_start = 0.25f;
  p.clip_end = 80.0f;
  p.matrix_world = some_camera_matrix();
  const Camera cam = Camera::make(p);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> ux(0.0f, 640.0f), uy(0.0f, 480.0f);
  for (int i = 0; i < 100; ++i) {
    const Ray r = cam.generate(ux(rng), uy(rng));
    const float depth_near = glm::dot(r.tnear * r.dir, -cam.axis_z);
    const float depth_far = glm::dot(r.tfar * r.dir, -cam.axis_z);
    EXPECT_NEAR(depth_near, p.clip_start, 1e-6f);
    EXPECT_NEAR(depth_far, p.clip_end, 1e-4f);
  }
}

// A pinhole projection written independently of Camera (focal length in pixels, principal
// point moved by the shift): the ray generated at the projected pixel must pass through the point.
TEST(Camera, ProjectedPointRoundTripsThroughGenerate) {
  CameraParams p = landscape();
  p.resolution_x = 800;
  p.resolution_y = 500;
  p.sensor_fit = SensorFit::Horizontal;
  p.lens = 42.0f;
  p.sensor_width = 30.0f;
  p.shift_x = 0.07f;
  p.shift_y = -0.12f;
  p.pixel_aspect_x = 1.0f;
  p.pixel_aspect_y = 1.25f;
  p.matrix_world = some_camera_matrix();
  const Camera cam = Camera::make(p);
  const Mat4 to_camera = glm::inverse(p.matrix_world);
  const float fx = p.lens / p.sensor_width * p.resolution_x;  // pixels per unit tangent across x
  const float fy = fx * p.pixel_aspect_x / p.pixel_aspect_y;  // taller pixels: fewer per unit
  const float cx = p.resolution_x / 2.0f - p.shift_x * p.resolution_x;
  const float cy = p.resolution_y / 2.0f + p.shift_y * p.resolution_x * p.pixel_aspect_x / p.pixel_aspect_y;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> sym(-1.0f, 1.0f), depth(1.0f, 50.0f);
  int tested = 0;
  for (int i = 0; i < 200; ++i) {
    const Vec3 local(sym(rng) * 0.4f, sym(rng) * 0.3f, -1.0f);
    const Vec3 world = Vec3(p.matrix_world * glm::vec4(local * depth(rng), 1.0f));
    const Vec3 c = Vec3(to_camera * glm::vec4(world, 1.0f));
    const float px = cx + fx * (c.x / -c.z), py = cy - fy * (c.y / -c.z);
    if (px < 0 || px >= 800 || py < 0 || py >= 500) continue;
    ++tested;
    const Ray r = cam.generate(px, py);
    const Vec3 to_point = world - r.org;
    const float t = glm::dot(to_point, r.dir);
    EXPECT_LT(glm::length(to_point - t * r.dir), 2e-5f * glm::length(to_point)) << px << " " << py;
  }
  EXPECT_GT(tested, 100);
}

TEST(Camera, ResolutionPercentageTruncatesLikeBlenderAndKeepsTheView) {
  CameraParams p = landscape();
  p.resolution_x = 1920;
  p.resolution_y = 1080;
  const Camera full = Camera::make(p);
  p.resolution_percentage = 33;
  const Camera small = Camera::make(p);
  EXPECT_EQ(small.width, 1920 * 33 / 100);  // 633.6 -> 633
  EXPECT_EQ(small.height, 1080 * 33 / 100);
  const Ray a = full.generate(1920.0f * 0.3f, 1080.0f * 0.8f);
  const Ray b = small.generate(small.width * 0.3f, small.height * 0.8f);
  // Truncation changes the aspect ratio by at most one pixel in 633.
  EXPECT_NEAR(glm::length(a.dir - b.dir), 0.0f, 1e-3f);
}

TEST(Camera, BorderMapsToPixelWindow) {
  CameraParams p = landscape();
  p.resolution_x = 200;
  p.resolution_y = 100;
  p.use_border = true;
  p.border_min_x = 0.25f;
  p.border_max_x = 0.755f;
  p.border_min_y = 0.1f;
  p.border_max_y = 0.5f;
  const Camera cam = Camera::make(p);
  // Blender truncates border * size; its y counts from the bottom, ours from the top.
  EXPECT_EQ(cam.window.x0, int(std::floor(0.25f * 200)));
  EXPECT_EQ(cam.window.x1, int(std::floor(0.755f * 200)));
  EXPECT_EQ(cam.window.y0, 100 - int(std::floor(0.5f * 100)));
  EXPECT_EQ(cam.window.y1, 100 - int(std::floor(0.1f * 100)));
  // The border lies below the image centre, so its rays look down; the full image stays the frame.
  EXPECT_EQ(cam.width, 200);
  EXPECT_LT(glm::dot(cam.generate(cam.window.x0 + 0.5f, cam.window.y0 + 0.5f).dir, cam.axis_y), 0.0f);
  p.border_min_x = p.border_min_y = 0.0f;
  p.border_max_x = p.border_max_y = 1.0f;
  const Camera whole = Camera::make(p);
  EXPECT_EQ(whole.window.x0, 0);
  EXPECT_EQ(whole.window.y0, 0);
  EXPECT_EQ(whole.window.x1, 200);
  EXPECT_EQ(whole.window.y1, 100);
}

TEST(Camera, RejectsInvalidSettings) {
  const auto bad = [](auto change) {
    CameraParams p = landscape();
    change(p);
    EXPECT_THROW(Camera::make(p), std::invalid_argument);
  };
  bad([](CameraParams& p) { p.resolution_x = 0; });
  bad([](CameraParams& p) { p.resolution_y = -5; });
  bad([](CameraParams& p) { p.resolution_percentage = 0; });
  bad([](CameraParams& p) {
    p.resolution_x = 1;
    p.resolution_percentage = 50;
  });  // 0 pixels
  bad([](CameraParams& p) { p.lens = 0.0f; });
  bad([](CameraParams& p) { p.lens = -35.0f; });
  bad([](CameraParams& p) { p.sensor_width = 0.0f; });
  bad([](CameraParams& p) {
    p.type = CameraType::Orthographic;
    p.ortho_scale = 0.0f;
  });
  bad([](CameraParams& p) { p.pixel_aspect_y = 0.0f; });
  bad([](CameraParams& p) { p.clip_end = p.clip_start; });
  bad([](CameraParams& p) { p.shift_x = NAN; });
  bad([](CameraParams& p) { p.matrix_world[3][1] = INFINITY; });
  bad([](CameraParams& p) { p.matrix_world[0][3] = 0.5f; });  // not affine
  bad([](CameraParams& p) { p.matrix_world[2] = glm::vec4(0.0f); });
  bad([](CameraParams& p) {
    p.use_border = true;
    p.border_min_x = 0.6f;
    p.border_max_x = 0.5f;
  });
  bad([](CameraParams& p) {
    p.use_border = true;
    p.border_min_y = 0.5f;
    p.border_max_y = 0.501f;
  });  // no pixel
  EXPECT_NO_THROW(Camera::make(landscape()));
}

// Depth of field (camera/thin_lens.h). The thin lens's defining property: every ray of a pixel,
// whatever its aperture point, passes through the point where the pinhole ray crosses the plane
// of focus; and the aperture points fill the aperture's shape uniformly.
namespace {

CameraParams with_dof(CameraParams p, float focus, float fstop, int blades = 0, float rotation = 0.0f,
                      float ratio = 1.0f) {
  p.use_dof = true;
  p.focus_distance = focus;
  p.aperture_fstop = fstop;
  p.aperture_blades = blades;
  p.aperture_rotation = rotation;
  p.aperture_ratio = ratio;
  return p;
}

// The aperture point of a lens ray in the camera's (x, y): where it crosses the lens plane (the
// plane through the camera position, perpendicular to the view axis).
Vec2 lens_point(const Camera& cam, const Ray& ray) {
  const float t = glm::dot(cam.position - ray.org, cam.axis_z) / glm::dot(ray.dir, cam.axis_z);
  const Vec3 q = ray.org + t * ray.dir - cam.position;
  return {glm::dot(q, cam.axis_x), glm::dot(q, cam.axis_y)};
}

std::vector<Vec2> aperture_points(const Camera& cam, int n) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<Vec2> out;
  // Relative to the pinhole ray's crossing: the camera position, or an orthographic pixel's point.
  const Vec2 centre = lens_point(cam, cam.generate(100.5f, 80.5f));
  for (int i = 0; i < n; ++i)
    out.push_back(lens_point(cam, cam.generate(100.5f, 80.5f, Vec2(u(rng), u(rng)))) - centre);
  return out;
}

}  // namespace

TEST(ThinLens, EveryLensRayCrossesThePinholeRaysPointOnThePlaneOfFocus) {
  for (CameraType type : {CameraType::Perspective, CameraType::Orthographic}) {
    for (int blades : {0, 6}) {
      CameraParams p = with_dof(landscape(), 3.5f, 0.4f, blades, 0.3f, 1.7f);
      p.type = type;
      p.matrix_world = some_camera_matrix();
      const Camera cam = Camera::make(p);
      ASSERT_GT(cam.lens.radius, 0.0f);
      std::mt19937 rng(3);
      std::uniform_real_distribution<float> u(0.0f, 1.0f);
      for (int i = 0; i < 200; ++i) {
        const float px = 640.0f * u(rng), py = 480.0f * u(rng);
        const Ray pin = cam.generate(px, py);
        // Where the pinhole ray reaches depth 3.5 along the view axis.
        const float t = (3.5f - glm::dot(pin.org - cam.position, -cam.axis_z)) / glm::dot(pin.dir, -cam.axis_z);
        const Vec3 focus = pin.org + t * pin.dir;
        for (int k = 0; k < 8; ++k) {
          const Ray ray = cam.generate(px, py, Vec2(u(rng), u(rng)));
          EXPECT_NEAR(glm::length(ray.dir), 1.0f, 1e-5f);
          const Vec3 to_focus = focus - ray.org;
          // Distance from the focus point to the lens ray's line.
          EXPECT_LT(glm::length(to_focus - glm::dot(to_focus, ray.dir) * ray.dir), 2e-5f * 3.5f);
          // Clipping stays by planes: the ray starts and ends at the clip depths.
          const Vec3 near = ray.org + ray.tnear * ray.dir, far = ray.org + ray.tfar * ray.dir;
          EXPECT_NEAR(glm::dot(near - cam.position, -cam.axis_z), p.clip_start, 1e-4f);
          EXPECT_NEAR(glm::dot(far - cam.position, -cam.axis_z), p.clip_end, 1e-3f);
        }
      }
    }
  }
}

TEST(ThinLens, RoundApertureIsUniformOnTheDiskOfRadiusLensOverTwiceFstop) {
  // Perspective: 35 mm / (2 x 0.7) = 25 mm; orthographic: 1 m / (2 x 0.7) (Cycles' rules).
  for (CameraType type : {CameraType::Perspective, CameraType::Orthographic}) {
    for (float ratio : {1.0f, 2.0f}) {
      CameraParams p = with_dof(landscape(), 2.0f, 0.7f, 0, 0.0f, ratio);
      p.type = type;
      const Camera cam = Camera::make(p);
      const double r = (type == CameraType::Perspective ? 0.035 : 1.0) / (2.0 * 0.7);
      ASSERT_NEAR(cam.lens.radius, r, 1e-6 * r);
      const int n = 200000;
      double mx = 0, my = 0, xx = 0, yy = 0;
      for (const Vec2& a : aperture_points(cam, n)) {
        // Inside the ellipse the anamorphic squeeze makes of the disk.
        ASSERT_LE(std::hypot(a.x * ratio, a.y), r * (1 + 1e-4));
        mx += a.x, my += a.y, xx += double(a.x) * a.x, yy += double(a.y) * a.y;
      }
      // Uniform on the disk of radius r: mean 0, E[x^2] = E[y^2] = r^2 / 4 (x divided by the ratio).
      // The bounds are five standard errors of independent samples: x's standard deviation is
      // r / 2, and x^2's is r^2 / 4 (E[x^4] = r^4 / 8), so E[x^2]'s relative error is 1 / sqrt(n).
      const double se = 1.0 / std::sqrt(double(n));
      EXPECT_NEAR(mx / n, 0.0, 5 * 0.5 * r * se);
      EXPECT_NEAR(my / n, 0.0, 5 * 0.5 * r * se);
      EXPECT_NEAR(xx / n * ratio * ratio / (r * r / 4), 1.0, 5 * se);
      EXPECT_NEAR(yy / n / (r * r / 4), 1.0, 5 * se);
    }
  }
}

TEST(ThinLens, BladesMakeAUniformRegularPolygonTurnedByTheRotation) {
  for (int blades : {3, 5, 8}) {
    const float rotation = 0.4f;
    const Camera cam = Camera::make(with_dof(landscape(), 2.0f, 1.0f, blades, rotation));
    const double r = 0.035 / 2.0, half = kPi / blades;
    const double inradius = r * std::cos(half);
    const int n = 200000;
    double rr = 0, rr4 = 0;
    int in_incircle = 0;
    double corner_reach = 0, edge_reach = 0;
    for (const Vec2& a : aperture_points(cam, n)) {
      // Inside every edge: the edges' outward normals point at rotation + 2 pi k / blades.
      for (int k = 0; k < blades; ++k) {
        const double phi = rotation + 2.0 * half * k;
        ASSERT_LE(a.x * std::cos(phi) + a.y * std::sin(phi), inradius * (1 + 1e-4));
      }
      const double a2 = double(a.x) * a.x + double(a.y) * a.y;
      rr += a2, rr4 += a2 * a2;
      in_incircle += std::hypot(a.x, a.y) < inradius;
      corner_reach = std::max(corner_reach, a.x * std::cos(rotation + half) + a.y * std::sin(rotation + half));
      edge_reach = std::max(edge_reach, a.x * std::cos(double(rotation)) + a.y * std::sin(double(rotation)));
    }
    // Uniform: the incircle holds its share of the polygon's area, and E[|p|^2] is the fan of
    // isosceles triangles' (1 + 2 cos^2(pi / n)) r^2 / 6 (a triangle's E[p p^T] is
    // (sum v v^T + (sum v)(sum v)^T) / 12).
    const double area = 0.5 * blades * r * r * std::sin(2.0 * half);
    EXPECT_NEAR(regular_polygon_area(blades) * r * r, area, 1e-6 * area);
    const double share = kPi * inradius * inradius / area;
    EXPECT_NEAR(double(in_incircle) / n, share, 5 * std::sqrt(share * (1 - share) / n));
    // Within five standard errors, estimated from the samples' own spread of |p|^2.
    const double mean_rr = rr / n, se = std::sqrt((rr4 / n - mean_rr * mean_rr) / n);
    EXPECT_NEAR(mean_rr, (1 + 2 * std::cos(half) * std::cos(half)) * r * r / 6, 5 * se);
    // The corners reach the circumradius, towards rotation + pi / n; the edges' midpoints the inradius.
    EXPECT_NEAR(corner_reach / r, 1.0, 0.01);
    EXPECT_NEAR(edge_reach / inradius, 1.0, 0.01);
  }
}

TEST(ThinLens, WithoutDepthOfFieldTheRaysAreThePinholesBitForBit) {
  for (CameraType type : {CameraType::Perspective, CameraType::Orthographic}) {
    CameraParams p = with_dof(landscape(), 2.0f, 0.1f, 6);
    p.use_dof = false;  // the other settings are ignored
    p.type = type;
    p.matrix_world = some_camera_matrix();
    const Camera cam = Camera::make(p);
    EXPECT_TRUE(cam.lens.pinhole());
    for (float px : {0.0f, 17.25f, 639.9f})
      for (float py : {0.0f, 240.5f, 479.9f}) {
        const Ray a = cam.generate(px, py), b = cam.generate(px, py, Vec2(0.9f, 0.1f));
        EXPECT_EQ(0, std::memcmp(&a, &b, sizeof(Ray)));
      }
  }
}

TEST(ThinLens, RejectsInvalidSettingsAndClampsZerosAsCycles) {
  const auto bad = [](auto change) {
    CameraParams p = with_dof(landscape(), 2.0f, 2.8f);
    change(p);
    EXPECT_THROW(Camera::make(p), std::invalid_argument);
  };
  bad([](CameraParams& p) { p.focus_distance = -1.0f; });
  bad([](CameraParams& p) { p.focus_distance = NAN; });
  bad([](CameraParams& p) { p.aperture_fstop = -2.0f; });
  bad([](CameraParams& p) { p.aperture_fstop = INFINITY; });
  bad([](CameraParams& p) { p.aperture_blades = -1; });
  bad([](CameraParams& p) { p.aperture_rotation = NAN; });
  bad([](CameraParams& p) { p.aperture_ratio = 0.0f; });
  bad([](CameraParams& p) { p.aperture_ratio = -1.0f; });
  // Blender allows a zero f-stop and focus distance; Cycles clamps both to 1e-5.
  const Camera cam = Camera::make(with_dof(landscape(), 0.0f, 0.0f, 2));
  EXPECT_FLOAT_EQ(cam.lens.focus_distance, 1e-5f);
  EXPECT_FLOAT_EQ(cam.lens.radius, 0.035f / 2e-5f);
  EXPECT_EQ(cam.lens.blades, 0);  // fewer than 3 blades: round
}

TEST(CameraCone, PerspectiveSpreadIsTheChordOfOnePixelsAngle) {
  // 36 mm sensor, 50 mm lens, 100 x 100 pixels: one pixel is 0.0072 on the plane at unit depth.
  CameraParams p;
  p.resolution_x = p.resolution_y = 100;
  p.matrix_world = some_camera_matrix();
  const Camera cam = Camera::make(p);
  const CameraCone cone = CameraCone::of(cam);
  const double s = 36.0 / 50.0 / 100.0;
  auto chord = [](double angle) { return 2.0 * std::sin(0.5 * angle); };
  // Along the view axis both steps turn the ray by atan(s).
  const RayCone centre = cone.of_ray(-cam.axis_z);
  EXPECT_EQ(centre.width, 0.0f);
  EXPECT_NEAR(centre.spread, chord(std::atan(s)), 1e-6);
  // Through (0.3, 0) on the unit-depth plane: the x step turns it by atan(0.3 + s) - atan(0.3),
  // the y step by the angle between (0.3, 0, -1) and (0.3, s, -1).
  const Vec3 dir = glm::normalize(0.3f * cam.axis_x - cam.axis_z);
  const double along_x = std::atan(0.3 + s) - std::atan(0.3);
  const double along_y = std::acos((0.09 + 1.0) / (std::sqrt(1.09) * std::sqrt(1.09 + s * s)));
  EXPECT_NEAR(cone.of_ray(dir).spread, 0.5 * (chord(along_x) + chord(along_y)), 2e-6);
  EXPECT_NEAR(cone.of_ray(dir).at(4.0f), 4.0 * 0.5 * (chord(along_x) + chord(along_y)), 1e-5);
}

TEST(CameraCone, OrthographicWidthIsOnePixelAndDoesNotSpread) {
  CameraParams p;
  p.type = CameraType::Orthographic;
  p.ortho_scale = 6.0f;
  p.resolution_x = 200;
  p.resolution_y = 100;
  const Camera cam = Camera::make(p);
  const RayCone cone = CameraCone::of(cam).of_ray(-cam.axis_z);
  EXPECT_FLOAT_EQ(cone.width, 6.0f / 200.0f);
  EXPECT_EQ(cone.spread, 0.0f);
  EXPECT_FLOAT_EQ(cone.at(100.0f), 6.0f / 200.0f);
  // A camera without constants (CameraCone{}): zero cones, the slope at the point.
  EXPECT_EQ(CameraCone{}.of_ray(Vec3(0, 0, -1)).spread, 0.0f);
}
