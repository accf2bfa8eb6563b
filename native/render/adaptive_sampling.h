// Adaptive sampling as Cycles defines it (use_adaptive_sampling, adaptive_threshold,
// adaptive_min_samples): a pixel stops taking samples once its noise estimate falls below the
// threshold. The estimate compares the pixel's mean over all its samples, I, with the mean over
// one half of them, A (Dammertz et al. 2010, "A hierarchical automatic stopping condition for
// Monte Carlo global illumination", section 2.1, applied per pixel):
//     error = |I - A|_1 / (1e-4 + sqrt(I_r + I_g + I_b))      (the sum above 1: divided by the sum)
// The half is every sample whose index has an odd count of bits set at odd positions (Christensen
// et al. 2018, section 10.2.1): on a Sobol-Owen sequence both halves stay stratified. The test
// runs after samples 16k - 1 (0-based) past the minimum, as in Cycles.
//
// What differs from Cycles: Cycles also keeps a converged pixel sampling while a neighbour is not
// (a one-pixel dilation over the image between rounds); TOYRT renders a pixel's samples in one
// go, so each pixel stops on its own estimate (docs/render.md).
#pragma once

#include "core/math.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace toyrt {

struct AdaptiveSettings {
  bool use = false;         // Cycles' use_adaptive_sampling (off by default, as TOYRT's add-on)
  float threshold = 0.01f;  // adaptive_threshold; 0: automatic, max(0.001, 1 / samples)
  int min_samples = 0;      // adaptive_min_samples; 0: automatic from the threshold
};

// The rule one render applies, resolved from the settings and the render's sample count.
struct AdaptiveRule {
  bool use = false;
  float threshold = 0.0f;  // the error bound compared against (Cycles scales the setting by 5)
  int min_samples = 0;     // no test before this many samples (at least 4)

  static AdaptiveRule resolve(const AdaptiveSettings& s, int samples) {
    AdaptiveRule r;
    if (!s.use) return r;
    r.use = true;
    const float t = s.threshold > 0.0f ? s.threshold : std::max(0.001f, 1.0f / float(std::max(samples, 1)));
    // Cycles' guess: threshold 0.1 -> 32 samples, 0.01 -> 64, 0.001 -> 128.
    r.min_samples =
        s.min_samples > 0 ? std::max(4, s.min_samples) : std::max(4, int(std::ceil(16.0f / std::pow(t, 0.3f))));
    r.threshold = 5.0f * t;
    return r;
  }

  // Whether sample `sample` (0-based, of the pixel's whole sequence) goes into the half A.
  static bool in_half(uint32_t sample) { return (__builtin_popcount(sample & 0xaaaaaaaau) & 1) != 0; }
  // Whether the pixel is tested after sample `sample` (0-based).
  bool tests_after(int sample) const { return sample > min_samples && (sample & 15) == 15; }
  // sum: the pixel's radiance summed over its n samples; half: summed over those in_half().
  bool converged(const Vec3& sum, const Vec3& half, int n) const {
    const float inv = 1.0f / float(n);
    const Vec3 mean = sum * inv, half_mean = half * (2.0f * inv);
    const Vec3 d = glm::abs(mean - half_mean);
    const float intensity = mean.x + mean.y + mean.z;
    const float normalize = intensity < 1.0f ? std::sqrt(std::max(intensity, 0.0f)) : intensity;
    return (d.x + d.y + d.z) / (1e-4f + normalize) < threshold;
  }
};

}  // namespace toyrt
