// A rough dielectric vertex (materials/dielectric_lobe.h): the lamps on both sides of the surface,
// one shadow-ray sample each from the side's own offset origin, weighted by the power heuristic
// against the lobe's sampling, then the continuation the lobe draws (a reflection or a
// transmission), whose ray collects the same lamps with the complementary weight (the
// integrator's visible_lights). As glossy_lighting.h: every lamp once (or one picked on
// emitter_dim - 1 where picks_one_lamp()), and one emissive triangle
// and one direction of the environment map (dimensions emitter_dim and emitter_dim + 1) from
// either side, whose light the continuation ray finds with the complementary weight.
#pragma once

#include "materials/dielectric_lobe.h"
#include "render/render_settings.h"
#include "scene/scene.h"

#include <cstdint>

namespace toyrt {

// radiance: the sampled light at p; wi, weight (f |cos| / pdf), pdf: the continuation (pdf 0: the
// path ends); origin: its ray's origin, offset to the side it leaves into.
struct DielectricStep {
  Vec3 radiance{0.0f};
  Vec3 wi{0.0f};
  Vec3 weight{0.0f};
  Vec3 origin{0.0f};
  float pdf = 0.0f;
};

// ng: the geometric normal on wo's side. Lamp j draws from Sobol-Owen dimension light_dim + j;
// the lobe's normal from lobe_dim (2D) and its side from side_dim (1D).
[[gnu::noinline]] DielectricStep dielectric_vertex(const Scene& scene, const Vec3& p, const Vec3& ng, TriangleRef self,
                                                   const DielectricLobe& lobe, uint32_t pixel, uint32_t sample,
                                                   uint32_t light_dim, uint32_t lobe_dim, uint32_t side_dim,
                                                   uint32_t emitter_dim, const IntegratorSettings& settings,
                                                   uint8_t receiver_set = 0);

}  // namespace toyrt
