#include "render/glossy_lighting.h"

#include "render/transparent_walk.h"
#include "sampling/sobol_owen.h"

#include <cmath>

namespace toyrt {

Vec3 glossy_direct_lighting(const Scene& scene, const Vec3& p, const Vec3& origin, const Vec3& ng,
                            const GlossyLobe& lobe, uint32_t pixel, uint32_t sample, uint32_t first_dim,
                            const IntegratorSettings& settings, uint8_t receiver_set) {
  const World& world = scene.world();
  Vec3 sum(0.0f);
  for (size_t j = 0; j < world.lights.size(); ++j) {
    // The lamps a glossy reflection shows are those visible to specular rays (Cycles' glossy
    // ray visibility), for their light as for their image.
    const LightVisibility v = world.light_visibility[j];
    // Light linking: a lamp that does not light this object adds nothing (lights/light_linking.h).
    if (!v.specular || !in_light_sets(v.receiver_sets, receiver_set)) continue;
    const LightSample ls =
        sample_light(world.lights[j], p, sobol_owen_2d(pixel, sample, first_dim + uint32_t(j), settings.seed),
                     settings.area_sampling);
    if (!ls.valid() || glm::dot(ng, ls.wi) <= 0.0f) continue;
    const BsdfEval e = evaluate_lobe(lobe, ls.wi);
    const float cos_i = glm::dot(lobe.frame.n, ls.wi);
    if (cos_i <= 0.0f || e.f == Vec3(0.0f)) continue;
    Vec3 tr(1.0f);  // what cut-outs on the way let through
    if (v.shadow) {
      const Ray shadow =
          std::isinf(ls.distance) ? Ray{origin, 0.0f, ls.wi, kInfinity} : Ray{origin, 0.0f, ls.point - origin, 1.0f};
      if (!shadow_passes(scene, shadow, settings.transparent_max_bounces, tr, v.blocker_sets)) continue;
    }
    // A delta lamp cannot be hit by the continuation ray: its sample is the only strategy.
    const float w = ls.delta ? 1.0f : power_heuristic(ls.pdf, e.pdf);
    sum += e.f * ls.radiance * tr * (cos_i * w / ls.pdf);
  }
  return sum;
}

GlossyStep glossy_vertex(const Scene& scene, const Vec3& p, const Vec3& origin, const Vec3& ng, const GlossyLobe& lobe,
                         uint32_t pixel, uint32_t sample, uint32_t light_dim, uint32_t lobe_dim,
                         const IntegratorSettings& settings, uint8_t receiver_set) {
  GlossyStep step;
  step.radiance = glossy_direct_lighting(scene, p, origin, ng, lobe, pixel, sample, light_dim, settings, receiver_set);
  const BsdfSample g = sample_lobe(lobe, sobol_owen_2d(pixel, sample, lobe_dim, settings.seed));
  if (!(g.pdf > 0.0f) || glm::dot(g.wi, ng) <= 0.0f) return step;
  step.wi = g.wi;
  step.weight = g.weight;
  step.pdf = g.pdf;
  return step;
}

}  // namespace toyrt
