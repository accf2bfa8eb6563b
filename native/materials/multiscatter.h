// Multiscatter GGX as Cycles 4.0+ renders it: the single-scatter lobe scaled up by the energy
// that light bouncing between microfacets would add (Kulla and Conty 2017, "Revisiting Physically
// Based Shading at Imageworks"). With E the lobe's directional albedo at wo and E_avg its average
// (sampling/ggx_albedo.h), a white lobe loses 1 - E, which 1 + (1 - E) / E puts back; a lobe with
// Fresnel keeps only part of each extra bounce, F_ms = Fss E_avg / (1 - Fss (1 - E_avg)) for its
// average single-bounce Fresnel Fss, so the factor is 1 + F_ms (1 - E) / E. It depends on wo
// only: the lobe's shape (and its sampling) stays the single-scatter one, as in Cycles.
#pragma once

#include "core/math.h"
#include "sampling/ggx_albedo.h"

namespace toyrt {

inline Vec3 multiscatter_scale(float roughness, float cos_o, const Vec3& fss) {
  const float e = ggx_albedo(roughness, cos_o), e_avg = ggx_average_albedo(roughness);
  const float missing = (1.0f - e) / e;
  const Vec3 f_ms = fss * e_avg / (Vec3(1.0f) - fss * (1.0f - e_avg));
  return Vec3(1.0f) + f_ms * missing;
}

}  // namespace toyrt
