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

// Reflectance at normal incidence, ((eta - 1) / (eta + 1))^2, and its inverse for eta >= 1 (f0
// kept below 0.99, as Blender does, so the answer stays finite).
inline float f0_from_ior(float eta) {
  const float r = (eta - 1.0f) / (eta + 1.0f);
  return r * r;
}
inline float ior_from_f0(float f0) {
  const float r = std::sqrt(std::clamp(f0, 0.0f, 0.99f));
  return (1.0f + r) / (1.0f - r);
}

// The cosine-weighted hemispherical average 2 int_0^1 F(mu) mu dmu: the share of uniformly
// incident light a smooth interface reflects. Below the critical cosine (eta < 1) F is 1 and the
// integral is exact; above it, where F is smooth, a 256-point midpoint rule (within 1e-4 of a fine
// integral: ggx_albedo_test).
inline float fresnel_dielectric_average(float eta) {
  constexpr int kN = 256;
  const float mu_c = eta < 1.0f ? std::sqrt(1.0f - eta * eta) : 0.0f;
  double sum = 0.0;
  for (int i = 0; i < kN; ++i) {
    const float mu = mu_c + (1.0f - mu_c) * (float(i) + 0.5f) / float(kN);
    sum += double(fresnel_dielectric(mu, eta)) * mu;
  }
  return float(double(mu_c) * mu_c + 2.0 * sum * (1.0 - mu_c) / kN);
}

}  // namespace toyrt
