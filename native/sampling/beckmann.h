// The Beckmann microfacet distribution, isotropic, in a local frame whose z axis is the
// macro-surface normal: D, Smith's Lambda by Walter et al.'s rational fit (2007, eq. 27; the one
// Cycles evaluates, so that masking matches it), and sampling of D(m) m.z. alpha = roughness^2,
// as for GGX (sampling/ggx.h).
#pragma once

#include "core/math.h"

#include <algorithm>
#include <cmath>

namespace toyrt {

// D(m) = exp(-tan^2 / alpha^2) / (pi alpha^2 cos^4), 0 below.
inline float beckmann_d(float alpha, const Vec3& m) {
  if (m.z <= 0.0f) return 0.0f;
  const float c2 = m.z * m.z, a2 = alpha * alpha;
  const float tan2 = (m.x * m.x + m.y * m.y) / c2;
  return std::exp(-tan2 / a2) / (kPi * a2 * c2 * c2);
}

// Lambda with a = 1 / (alpha tan): (1 - 1.259 a + 0.396 a^2) / (3.535 a + 2.181 a^2) below
// a = 1.6, 0 above (within 0.35 % of the exact erf form); infinite at the horizon.
inline float beckmann_lambda(float alpha, const Vec3& w) {
  if (w.z <= 0.0f) return kInfinity;
  const float s = std::sqrt(std::max(0.0f, w.x * w.x + w.y * w.y));
  if (!(s > 0.0f)) return 0.0f;
  const float a = w.z / (alpha * s);
  if (a >= 1.6f) return 0.0f;
  return (1.0f - 1.259f * a + 0.396f * a * a) / (3.535f * a + 2.181f * a * a);
}

// A normal with density D(m) m.z: tan^2 = -alpha^2 ln(1 - u.x), phi = 2 pi u.y.
inline Vec3 beckmann_sample_normal(float alpha, const Vec2& u) {
  const float tan2 = -alpha * alpha * std::log(std::max(1.0f - u.x, 1e-30f));
  const float cos_t = 1.0f / std::sqrt(1.0f + tan2), sin_t = std::sqrt(std::max(0.0f, 1.0f - cos_t * cos_t));
  const float phi = 2.0f * kPi * u.y;
  return Vec3(sin_t * std::cos(phi), sin_t * std::sin(phi), cos_t);
}

}  // namespace toyrt
