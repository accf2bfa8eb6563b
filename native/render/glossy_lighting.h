// Light arriving at a glossy vertex (materials/glossy_lobe.h): one shadow-ray sample per lamp,
// weighted by the power heuristic against the lobe's own sampling, whose continuation ray
// collects the same lamps with the complementary weight (the integrator's visible_lights).
// Only lamps are light-sampled here: the world, the environment and emissive meshes are found by
// the continuation ray alone (weight 1), which is unbiased and keeps this loop as small as the
// diffuse one; every lamp is sampled (no one-light selection) so that the weight a lamp seen by
// the continuation ray needs is its own pdf, not a selection probability.
#pragma once

#include "materials/glossy_lobe.h"
#include "render/render_settings.h"
#include "scene/scene.h"

#include <cstdint>

namespace toyrt {

// The power heuristic's weight (exponent 2) of a sample drawn with density `pdf` against another
// strategy of density `other` at the same direction, one sample each (Veach 1997, 9.2.4).
inline float power_heuristic(float pdf, float other) {
  const float a = pdf * pdf, b = other * other;
  return a > 0.0f ? a / (a + b) : 0.0f;
}

// p: the hit point; origin: its shadow-ray origin (offset along ng); ng: the geometric normal on
// wo's side. Lamp j draws its sample from Sobol-Owen dimension first_dim + j.
Vec3 glossy_direct_lighting(const Scene& scene, const Vec3& p, const Vec3& origin, const Vec3& ng,
                            const GlossyLobe& lobe, uint32_t pixel, uint32_t sample, uint32_t first_dim,
                            const IntegratorSettings& settings, uint8_t receiver_set = 0);

// A glossy vertex's whole work: its lamps' light (glossy_direct_lighting, lamp j from dimension
// light_dim + j) and the continuation the lobe draws from dimension lobe_dim: direction, weight
// f cos / pdf and pdf (0: the path ends, the sample left below the geometric surface). Out of
// line, so the integrator's loop, which a Lambert-only scene runs, stays the size it was.
struct GlossyStep {
  Vec3 radiance{0.0f};
  Vec3 wi{0.0f};
  Vec3 weight{0.0f};
  float pdf = 0.0f;
};
[[gnu::noinline]] GlossyStep glossy_vertex(const Scene& scene, const Vec3& p, const Vec3& origin, const Vec3& ng,
                                           const GlossyLobe& lobe, uint32_t pixel, uint32_t sample, uint32_t light_dim,
                                           uint32_t lobe_dim, const IntegratorSettings& settings,
                                           uint8_t receiver_set = 0);

}  // namespace toyrt
