// Moves a ray origin off the surface it starts on, so a shadow or refracted ray does not hit
// that surface again (Waechter and Binder 2019, "A Fast and Robust Method for Avoiding
// Self-Intersection", Ray Tracing Gems ch. 6). Far from the origin it steps a fixed number of
// ulps along the normal, which scales with the coordinate's magnitude and so with its rounding
// error; near the origin, where ulps get tiny, it adds a small fixed distance instead.
#pragma once

#include "core/math.h"

#include <cstring>

namespace toyrt {

// p: a point on the surface (e.g. a hit point); n: the geometric normal on the side the new ray
// leaves into (flip it for rays going through the surface). n need not be normalised but should
// be of unit order.
inline Vec3 offset_ray_origin(const Vec3& p, const Vec3& n) {
  constexpr float kOrigin = 1.0f / 32.0f;  // below this |coordinate|, offset by distance
  constexpr float kFloatScale = 1.0f / 65536.0f;
  constexpr float kIntScale = 256.0f;  // ulps per unit of normal
  Vec3 out;
  for (int a = 0; a < 3; ++a) {
    // A non-finite or huge normal would overflow the conversion (undefined behaviour): no step.
    const float scaled = kIntScale * n[a];
    const int32_t step = std::fabs(scaled) < 1e6f ? int32_t(scaled) : 0;
    int32_t bits;
    std::memcpy(&bits, &p[a], sizeof bits);
    // Adding to the bit pattern moves away from zero for positive steps on a positive number:
    // flip the step's sign for negative coordinates so the move follows n.
    bits += p[a] < 0.0f ? -step : step;
    float stepped;
    std::memcpy(&stepped, &bits, sizeof stepped);
    out[a] = std::fabs(p[a]) < kOrigin ? p[a] + kFloatScale * n[a] : stepped;
  }
  return out;
}

}  // namespace toyrt
