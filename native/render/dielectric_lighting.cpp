#include "render/dielectric_lighting.h"

#include "geometry/offset_ray.h"
#include "render/glossy_lighting.h"
#include "render/transparent_walk.h"
#include "sampling/sobol_owen.h"

#include <cmath>

namespace toyrt {

DielectricStep dielectric_vertex(const Scene& scene, const Vec3& p, const Vec3& ng, const DielectricLobe& lobe,
                                 uint32_t pixel, uint32_t sample, uint32_t light_dim, uint32_t lobe_dim,
                                 uint32_t side_dim, uint32_t emitter_dim, const IntegratorSettings& settings,
                                 uint8_t receiver_set) {
  DielectricStep step;
  const Vec3 above = offset_ray_origin(p, ng), below = offset_ray_origin(p, -ng);
  const World& world = scene.world();
  for (size_t j = 0; j < world.lights.size(); ++j) {
    // Lamps seen through or in glass are those visible to specular rays (Cycles' glossy and
    // transmission visibility, one flag here), for their light as for their image.
    const LightVisibility v = world.light_visibility[j];
    // Light linking: a lamp that does not light this object adds nothing (lights/light_linking.h).
    if (!v.specular || !in_light_sets(v.receiver_sets, receiver_set)) continue;
    const LightSample ls =
        sample_light(world.lights[j], p, sobol_owen_2d(pixel, sample, light_dim + uint32_t(j), settings.seed),
                     settings.area_sampling);
    if (!ls.valid()) continue;
    // The side the lamp is on, by the real surface, must agree with the shading frame's.
    const float side = glm::dot(ng, ls.wi), cos_i = glm::dot(lobe.frame.n, ls.wi);
    if (side == 0.0f || (side > 0.0f) != (cos_i > 0.0f)) continue;
    const BsdfEval e = dielectric_eval(lobe, ls.wi);
    if (e.f == Vec3(0.0f)) continue;
    const Vec3 origin = side > 0.0f ? above : below;
    Vec3 tr(1.0f);  // what cut-outs on the way let through
    if (v.shadow) {
      const Ray shadow =
          std::isinf(ls.distance) ? Ray{origin, 0.0f, ls.wi, kInfinity} : Ray{origin, 0.0f, ls.point - origin, 1.0f};
      if (!shadow_passes(scene, shadow, settings.transparent_max_bounces, tr, v.blocker_sets)) continue;
    }
    const float w = ls.delta ? 1.0f : power_heuristic(ls.pdf, e.pdf);
    step.radiance += e.f * ls.radiance * tr * (std::abs(cos_i) * w / ls.pdf);
  }
  const LobeVertex lv{nullptr, &lobe, p, ng, above, below};
  if (scene.any_emission())
    step.radiance += lobe_emitter_lighting(scene, lv, sobol_owen_2d(pixel, sample, emitter_dim, settings.seed),
                                           settings, receiver_set);
  if (samples_environment_at_lobes(world))
    step.radiance +=
        lobe_environment_lighting(scene, lv, sobol_owen_2d(pixel, sample, emitter_dim + 1, settings.seed), settings);
  const BsdfSample g = dielectric_sample(lobe, sobol_owen_2d(pixel, sample, lobe_dim, settings.seed),
                                         sobol_owen_1d(pixel, sample, side_dim, settings.seed));
  if (!(g.pdf > 0.0f)) return step;
  const float side = glm::dot(g.wi, ng), cos_i = glm::dot(lobe.frame.n, g.wi);
  if (side == 0.0f || (side > 0.0f) != (cos_i > 0.0f)) return step;  // the shading frame's side is wrong
  step.wi = g.wi;
  step.weight = g.weight;
  step.pdf = g.pdf;
  step.origin = side > 0.0f ? above : below;
  return step;
}

}  // namespace toyrt
