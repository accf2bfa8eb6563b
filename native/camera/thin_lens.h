// The camera's thin lens: Blender's depth of field (camera.dof) as Cycles renders it. A ray for
// a point of the view plane starts on the aperture, in the lens plane through the camera, and
// aims at the point where the pinhole ray crosses the plane of focus: everything on that plane
// is sharp, and a point at depth d is spread over the aperture's shape scaled by
// |d - focus_distance| / d (the circle of confusion), whatever the shape.
#pragma once

#include "sampling/warp.h"

namespace toyrt {

struct ThinLens {
  float radius = 0.0f;           // aperture radius in metres; 0 is a pinhole (no depth of field)
  float focus_distance = 10.0f;  // depth of the plane of focus along the view axis, m
  int blades = 0;                // 0 for a round aperture, else the polygon's corner count (>= 3)
  float rotation = 0.0f;         // the polygon's rotation, radians
  float inv_ratio = 1.0f;        // 1 / Blender's aperture_ratio: the anamorphic squeeze of x

  bool pinhole() const { return radius == 0.0f; }

  // A point of the aperture in the camera's (x, y), metres, from a point u of [0, 1)^2: uniform
  // over the disk (concentric map: it keeps u's strata) or the regular polygon inscribed in it,
  // then x scaled by inv_ratio as Cycles' anamorphic bokeh does.
  Vec2 sample(const Vec2& u) const {
    Vec2 p = blades == 0 ? sample_uniform_disk_concentric(u) : sample_uniform_regular_polygon(u, blades, rotation);
    p.x *= inv_ratio;
    return radius * p;
  }
};

}  // namespace toyrt
