// Exact Fresnel reflectance of a dielectric interface for unpolarised light: the mean of the s
// and p reflectances from Fresnel's equations,
//     r_s = (cos_i - eta cos_t) / (cos_i + eta cos_t),   r_p = (eta cos_i - cos_t) / (eta cos_i + cos_t),
//     F = (r_s^2 + r_p^2) / 2,
// with eta = n_t / n_i (far side over incident side) and Snell's sin_t = sin_i / eta. Beyond the
// critical angle (sin_t >= 1) F = 1: total internal reflection.
#pragma once

#include <algorithm>
#include <cmath>

namespace toyrt {

// cos_i: cosine between the incident direction and the normal on its side (clamped to [0, 1]).
inline float fresnel_dielectric(float cos_i, float eta) {
  cos_i = std::clamp(cos_i, 0.0f, 1.0f);
  const float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0f) return 1.0f;
  const float cos_t = std::sqrt(1.0f - sin2_t);
  const float rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  const float rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5f * (rs * rs + rp * rp);
}

}  // namespace toyrt
