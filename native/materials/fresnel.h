// Exact Fresnel reflectance of a dielectric interface for unpolarised light: the mean of the s
// and p reflectances from Fresnel's equations,
//     r_s = (cos_i - eta cos_t) / (cos_i + eta cos_t),   r_p = (eta cos_i - cos_t) / (eta cos_i + cos_t),
//     F = (r_s^2 + r_p^2) / 2,
// with eta = n_t / n_i (far side over incident side) and Snell's sin_t = sin_i / eta. Beyond the
// critical angle (sin_t >= 1) F = 1: total internal reflection.
#pragma once

#include "core/math.h"

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

// Blender 4.0+'s metal Fresnel, F82-tint (Hoffman 2023, "Generalization of Adobe's Fresnel
// Model"): Schlick's curve less a dip near grazing, F(c) = mix(f0, 1, (1 - c)^5) - b c (1 - c)^6,
// clamped to [0, 1], where b makes F at c = 1/7 (about 82 degrees) Schlick's value there times
// the tint: b = Schlick(1/7) (1 - tint) / ((1/7) (6/7)^6).
inline Vec3 f82_tint_b(const Vec3& f0, const Vec3& tint) {
  constexpr float k = 6.0f / 7.0f, k5 = (k * k) * (k * k) * k;
  return glm::mix(f0, Vec3(1.0f), k5) * (7.0f / (k5 * k)) * (Vec3(1.0f) - tint);
}
inline Vec3 fresnel_f82(float c, const Vec3& f0, const Vec3& b) {
  c = std::clamp(c, 0.0f, 1.0f);
  const float m = 1.0f - c, m5 = (m * m) * (m * m) * m;
  return glm::clamp(glm::mix(f0, Vec3(1.0f), m5) - b * (c * m5 * m), Vec3(0.0f), Vec3(1.0f));
}
// Its hemispherical average 2 int F(mu) mu dmu, term by term (without the clamp):
// 2 int mu (1 - mu)^5 = 1 / 21 and 2 int mu^2 (1 - mu)^6 = 2 B(3, 7) = 1 / 126.
inline Vec3 f82_average(const Vec3& f0, const Vec3& b) {
  return glm::mix(f0, Vec3(1.0f), 1.0f / 21.0f) - b * (1.0f / 126.0f);
}

}  // namespace toyrt
