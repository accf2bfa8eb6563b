#include "render/render_settings.h"

#include "core/parallel.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace toyrt {

LightSampling parse_light_sampling(const std::string& name) {
  if (name == "auto") return LightSampling::Auto;
  if (name == "all") return LightSampling::All;
  if (name == "one") return LightSampling::One;
  throw std::invalid_argument("light_sampling must be 'auto', 'all' or 'one', got '" + name + "'");
}

const char* light_sampling_name(LightSampling sampling) {
  switch (sampling) {
    case LightSampling::Auto:
      return "auto";
    case LightSampling::All:
      return "all";
    case LightSampling::One:
      return "one";
  }
  return "?";
}

LightSampling resolve_light_sampling(LightSampling sampling, size_t light_count) {
  if (sampling != LightSampling::Auto) return sampling;
  return light_count > kAllLightsUpTo ? LightSampling::One : LightSampling::All;
}

void RenderSettings::check() const {
  if (samples < 1) throw std::invalid_argument("samples must be at least 1");
  if (first_sample < 0) throw std::invalid_argument("first_sample must be >= 0");
  if (samples > std::numeric_limits<int>::max() - first_sample)
    throw std::invalid_argument("first_sample + samples must stay below 2^31");
  if (tile_size < 1) throw std::invalid_argument("tile_size must be at least 1");
  if (integrator.max_specular_depth < 0) throw std::invalid_argument("max_specular_depth must be >= 0");
  if (integrator.split_depth < 0) throw std::invalid_argument("split_depth must be >= 0");
  if (integrator.transparent_max_bounces < 0) throw std::invalid_argument("transparent_max_bounces must be >= 0");
  if (!(adaptive.threshold >= 0.0f) || !std::isfinite(adaptive.threshold))
    throw std::invalid_argument("adaptive_threshold must be a finite number >= 0");
  if (adaptive.min_samples < 0) throw std::invalid_argument("adaptive_min_samples must be >= 0");
  if (!(time_limit >= 0.0) || !std::isfinite(time_limit))
    throw std::invalid_argument("time_limit must be a finite number of seconds >= 0");
  check_threads(threads);
}

}  // namespace toyrt
