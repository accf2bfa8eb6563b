#include "render/glossy_lighting.h"

#include "lights/light_selector.h"
#include "materials/closure_mixture.h"
#include "render/transparent_walk.h"
#include "sampling/sobol_owen.h"

#include <cmath>

namespace toyrt {

LobeAnswer lobe_towards(const LobeVertex& v, const Vec3& wi) {
  LobeAnswer a;
  if (v.mixture) {
    a.cos = glm::dot(v.mixture->second_glossy.frame.n, wi);
    if (a.cos <= 0.0f || glm::dot(v.ng, wi) <= 0.0f) return a;
    a.e = mixture_eval(*v.mixture, wi);
    a.origin = v.above;
    // One visibility for the whole mixture, the glossy closures': a lamp hidden from glossy rays
    // alone leaves the diffuse part unlit here too, and one hidden from diffuse rays alone still
    // lights it (docs/render.md, 3.x's Clearcoat).
    a.seen_by = kVisibleGlossy;
    return a;
  }
  if (v.glossy) {
    a.cos = glm::dot(v.glossy->frame.n, wi);
    if (a.cos <= 0.0f || glm::dot(v.ng, wi) <= 0.0f) return a;
    a.e = evaluate_lobe(*v.glossy, wi);
    a.origin = v.above;
    a.seen_by = kVisibleGlossy;
    return a;
  }
  // The side the light is on, by the real surface, must agree with the shading frame's.
  const float side = glm::dot(v.ng, wi), cos = glm::dot(v.dielectric->frame.n, wi);
  if (side == 0.0f || (side > 0.0f) != (cos > 0.0f)) return a;
  a.e = dielectric_eval(*v.dielectric, wi);
  a.cos = std::abs(cos);
  a.origin = side > 0.0f ? v.above : v.below;
  a.seen_by = side > 0.0f ? kVisibleGlossy : kVisibleTransmission;
  return a;
}

Vec3 lobe_lamp_lighting(const Scene& scene, const LobeVertex& v, uint32_t pixel, uint32_t sample, uint32_t first_dim,
                        uint32_t pick_dim, const IntegratorSettings& settings, uint8_t receiver_set) {
  const World& world = scene.world();
  Vec3 sum(0.0f);
  auto add = [&](size_t j, float select_probability, uint32_t dim) {
    // A lamp lights a reflection or a refraction as it is seen by that kind of ray (Cycles'
    // glossy and transmission visibility), for its light as for its image: checked by side below.
    const LightVisibility lamp = world.light_visibility[j];
    // Light linking: a lamp that does not light this object adds nothing (lights/light_linking.h).
    if (!(lamp.glossy || lamp.transmission) || !in_light_sets(lamp.receiver_sets, receiver_set)) return;
    const LightSample ls =
        sample_light(world.lights[j], v.p, sobol_owen_2d(pixel, sample, dim, settings.seed), settings.area_sampling);
    if (!ls.valid()) return;
    const LobeAnswer a = lobe_towards(v, ls.wi);
    if (a.e.f == Vec3(0.0f) || !lamp.seen_by(a.seen_by)) return;
    Vec3 tr(1.0f);  // what cut-outs on the way let through
    if (lamp.shadow) {
      // A light at infinity (the sun) is left along wi; the others end where the sample is.
      const Ray shadow = std::isinf(ls.distance) ? Ray{a.origin, 0.0f, ls.wi, kInfinity, v.self}
                                                 : Ray{a.origin, 0.0f, ls.point - a.origin, 1.0f, v.self};
      if (!shadow_passes(scene, shadow, settings.transparent_max_bounces, tr, lamp.blocker_sets)) return;
    }
    // A delta lamp cannot be hit by the continuation ray: its sample is the only strategy.
    const float pdf = ls.pdf * select_probability;
    const float w = ls.delta ? 1.0f : power_heuristic(pdf, a.e.pdf);
    sum += a.e.f * ls.radiance * tr * (a.cos * w / pdf);
  };
  if (picks_one_lamp(world, settings)) {
    const LightSelector selector(world.lights, scene.light_tree(), scene.light_receiver_sets());
    const LightSelection pick =
        selector.select(v.p, v.tree_normal(), sobol_owen_1d(pixel, sample, pick_dim, settings.seed), receiver_set);
    if (pick.found()) add(size_t(pick.index), pick.probability, first_dim);
  } else {
    for (size_t j = 0; j < world.lights.size(); ++j) add(j, 1.0f, first_dim + uint32_t(j));
  }
  return sum;
}

Vec3 lobe_emitter_lighting(const Scene& scene, const LobeVertex& v, const Vec2& u, const IntegratorSettings& settings,
                           uint8_t receiver_set) {
  const MeshEmitters& emitters = scene.emitters();
  if (emitters.empty()) return Vec3(0.0f);
  EmitterPoint where;
  const LightSample ls = sample_emitters(emitters, v.p, v.tree_normal(), u, &where);
  if (!ls.valid()) return Vec3(0.0f);
  const LobeAnswer a = lobe_towards(v, ls.wi);
  if (a.e.f == Vec3(0.0f)) return Vec3(0.0f);
  // The emitters are gathered from objects diffuse rays see; the continuation ray passes those
  // the lobe's kind of ray does not see, so their light is not sampled here either.
  const uint64_t key = emitters.keys[where.index];
  const Instance& inst = scene.instance(uint32_t(key >> 32));
  if (!(inst.visibility & a.seen_by) || !in_light_sets(inst.light_receivers, receiver_set)) return Vec3(0.0f);
  Vec3 tr(1.0f);
  if (!shadow_passes(scene, Ray{a.origin, 0.0f, ls.point - a.origin, 1.0f, v.self}, settings.transparent_max_bounces,
                     tr))
    return Vec3(0.0f);
  const Vec3 radiance = emitters.triangles[where.index].textured ? scene.emitted_at(key, where.b) : ls.radiance;
  return a.e.f * radiance * tr * (a.cos * power_heuristic(ls.pdf, a.e.pdf) / ls.pdf);
}

Vec3 lobe_environment_lighting(const Scene& scene, const LobeVertex& v, const Vec2& u,
                               const IntegratorSettings& settings) {
  const World& world = scene.world();
  const EnvironmentSample es =
      sample_environment(world.environment, scene.textures()[size_t(world.environment.texture)], u);
  if (!(es.pdf > 0.0f)) return Vec3(0.0f);
  const LobeAnswer a = lobe_towards(v, es.wi);
  if (a.e.f == Vec3(0.0f)) return Vec3(0.0f);
  // The map as the lobe's own ray of that kind would see it (the world's ray visibility).
  if (!background_visible(world, a.seen_by == kVisibleGlossy ? RayKind::Glossy : RayKind::Transmission))
    return Vec3(0.0f);
  Vec3 tr(1.0f);
  if (!shadow_passes(scene, Ray{a.origin, 0.0f, es.wi, kInfinity, v.self}, settings.transparent_max_bounces, tr))
    return Vec3(0.0f);
  return a.e.f * es.radiance * tr * (a.cos * power_heuristic(es.pdf, a.e.pdf) / es.pdf);
}

float lobe_emitter_hit_weight(const Scene& scene, const LobeOrigin& from, float bsdf_pdf, const Vec3& wi, uint64_t key,
                              const Vec3& hit_p) {
  const MeshEmitters& emitters = scene.emitters();
  const int64_t index = emitters.index_of(key);
  if (index < 0) return 1.0f;  // not sampled as a light (emission sampling None): the ray alone finds it
  return power_heuristic(bsdf_pdf,
                         emitter_pdf(emitters, from.p, from.n, size_t(index), wi, glm::dot(hit_p - from.p, wi)));
}

float lobe_environment_hit_weight(const Scene& scene, float bsdf_pdf, const Vec3& wi) {
  return power_heuristic(bsdf_pdf, environment_pdf(scene.world().environment, wi));
}

Vec3 lobe_vertex_lighting(const Scene& scene, const LobeVertex& v, uint32_t pixel, uint32_t sample, uint32_t light_dim,
                          uint32_t emitter_dim, const IntegratorSettings& settings, uint8_t receiver_set) {
  Vec3 sum = lobe_lamp_lighting(scene, v, pixel, sample, light_dim, emitter_dim - 1, settings, receiver_set);
  if (scene.any_emission())
    sum += lobe_emitter_lighting(scene, v, sobol_owen_2d(pixel, sample, emitter_dim, settings.seed), settings,
                                 receiver_set);
  if (samples_environment_at_lobes(scene.world()))
    sum += lobe_environment_lighting(scene, v, sobol_owen_2d(pixel, sample, emitter_dim + 1, settings.seed), settings);
  return sum;
}

GlossyStep glossy_vertex(const Scene& scene, const Vec3& p, const Vec3& origin, const Vec3& ng, TriangleRef self,
                         const GlossyLobe& lobe, uint32_t pixel, uint32_t sample, uint32_t light_dim, uint32_t lobe_dim,
                         uint32_t emitter_dim, const IntegratorSettings& settings, uint8_t receiver_set) {
  GlossyStep step;
  const LobeVertex v{&lobe, nullptr, p, ng, origin, origin, self};
  step.radiance = lobe_vertex_lighting(scene, v, pixel, sample, light_dim, emitter_dim, settings, receiver_set);
  const BsdfSample g = sample_lobe(lobe, sobol_owen_2d(pixel, sample, lobe_dim, settings.seed));
  if (!(g.pdf > 0.0f) || glm::dot(g.wi, ng) <= 0.0f) return step;
  step.wi = g.wi;
  step.weight = g.weight;
  step.pdf = g.pdf;
  return step;
}

GlossyStep mixture_vertex(const Scene& scene, const Vec3& p, const Vec3& origin, const Vec3& ng, TriangleRef self,
                          const Scatter& mixture, uint32_t pixel, uint32_t sample, uint32_t light_dim,
                          uint32_t lobe_dim, uint32_t pick_dim, uint32_t emitter_dim,
                          const IntegratorSettings& settings, uint8_t receiver_set) {
  GlossyStep step;
  LobeVertex v{nullptr, nullptr, p, ng, origin, origin, self};
  v.mixture = &mixture;
  step.radiance = lobe_vertex_lighting(scene, v, pixel, sample, light_dim, emitter_dim, settings, receiver_set);
  bool diffuse = false;
  const BsdfSample g = mixture_sample(mixture, sobol_owen_1d(pixel, sample, pick_dim, settings.seed),
                                      sobol_owen_2d(pixel, sample, lobe_dim, settings.seed), diffuse);
  if (!(g.pdf > 0.0f) || glm::dot(g.wi, ng) <= 0.0f) return step;
  step.wi = g.wi;
  step.weight = g.weight;
  step.pdf = g.pdf;
  step.diffuse = diffuse;
  return step;
}

}  // namespace toyrt
