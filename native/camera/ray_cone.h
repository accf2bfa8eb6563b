// A ray's footprint as Cycles 3.x carries it (its "compact" ray differentials, a cone): the
// footprint's width where the ray starts and its growth per metre travelled. Cycles before 4.4
// differences a Bump node's height over this footprint (render/normal_mapping.cpp); from 4.4 on it
// takes the slope at the point, and nothing else in TOYRT reads it.
//
// What 3.4's kernel does (camera/camera.h, util/differential.h, integrator/shade_surface.h):
//   - a perspective camera ray's spread dD is the mean of |normalize(D + dx) - normalize(D)| over a
//     one-pixel step dx right and dy up on the view plane (D through the pixel, before the lens),
//     and its width dP is 0 at the camera (the near clip offset is dD times the distance to it);
//   - an orthographic ray's width is one pixel's width in metres (Cycles uses the x step for both
//     axes) and its spread is 0;
//   - at a hit, width = dP + t dD (the distance along the ray, not divided by any cosine);
//   - a bounce (reflection, refraction, a transparent crossing) starts the next ray with the hit's
//     width and keeps the spread: dD is never rewritten after the camera, so a reflected floor's
//     footprint is the camera's spread times the whole path length.
#pragma once

#include "core/math.h"

namespace toyrt {

struct Camera;

struct RayCone {
  float width = 0.0f;   // metres, where the ray starts
  float spread = 0.0f;  // metres of width per metre along the ray
  float at(float distance) const { return width + spread * distance; }
};

// A camera's constants for the cones of its rays. The default (zero steps) gives zero cones:
// bumps then take the slope at the point.
struct CameraCone {
  bool perspective = false;
  Vec3 axis_x{1, 0, 0}, axis_y{0, 1, 0}, axis_z{0, 0, 1};  // the camera's unit world axes (view along -z)
  // Perspective: one pixel's step on the view plane at unit depth; orthographic: step_x is one
  // pixel's width in metres.
  float step_x = 0.0f, step_y = 0.0f;

  static CameraCone of(const Camera& camera);
  // The cone of the camera ray along unit world direction `dir`. With depth of field Cycles reads
  // the pinhole direction through the pixel; the lens ray's own differs from it at second order.
  RayCone of_ray(const Vec3& dir) const;
};

}  // namespace toyrt
