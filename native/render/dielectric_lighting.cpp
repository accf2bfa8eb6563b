#include "render/dielectric_lighting.h"

#include "geometry/offset_ray.h"
#include "lights/light_selector.h"
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
  auto add = [&](size_t j, float select_probability, uint32_t dim) {
    // Lamps seen through or in glass are those visible to specular rays (Cycles' glossy and
    // transmission visibility, one flag here), for their light as for their image.
    const LightVisibility v = world.light_visibility[j];
    // Light linking: a lamp that does not light this object adds nothing (lights/light_linking.h).
    if (!v.specular || !in_light_sets(v.receiver_sets, receiver_set)) return;
    const LightSample ls =
        sample_light(world.lights[j], p, sobol_owen_2d(pixel, sample, dim, settings.seed), settings.area_sampling);
    if (!ls.valid()) return;
    // The side the lamp is on, by the real surface, must agree with the shading frame's.
    const float side = glm::dot(ng, ls.wi), cos_i = glm::dot(lobe.frame.n, ls.wi);
    if (side == 0.0f || (side > 0.0f) != (cos_i > 0.0f)) return;
    const BsdfEval e = dielectric_eval(lobe, ls.wi);
    if (e.f == Vec3(0.0f)) return;
    const Vec3 origin = side > 0.0f ? above : below;
    Vec3 tr(1.0f);  // what cut-outs on the way let through
    if (v.shadow) {
      const Ray shadow =
          std::isinf(ls.distance) ? Ray{origin, 0.0f, ls.wi, kInfinity} : Ray{origin, 0.0f, ls.point - origin, 1.0f};
      if (!shadow_passes(scene, shadow, settings.transparent_max_bounces, tr, v.blocker_sets)) return;
    }
    const float pdf = ls.pdf * select_probability;
    const float w = ls.delta ? 1.0f : power_heuristic(pdf, e.pdf);
    step.radiance += e.f * ls.radiance * tr * (std::abs(cos_i) * w / pdf);
  };
  if (picks_one_lamp(world, settings)) {
    // Light from both sides: no normal bounds the lamps' importance (LobeVertex::tree_normal).
    const LightSelector selector(world.lights, scene.light_tree(), scene.light_receiver_sets());
    const LightSelection pick =
        selector.select(p, Vec3(0.0f), sobol_owen_1d(pixel, sample, emitter_dim - 1, settings.seed), receiver_set);
    if (pick.found()) add(size_t(pick.index), pick.probability, light_dim);
  } else {
    for (size_t j = 0; j < world.lights.size(); ++j) add(j, 1.0f, light_dim + uint32_t(j));
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
