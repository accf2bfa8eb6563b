// Light arriving at a glossy vertex (materials/glossy_lobe.h): shadow-ray samples of the lamps,
// one emissive triangle and one direction of the environment map, each weighted by the power
// heuristic against the lobe's own sampling, whose continuation ray collects the same light with
// the complementary weight (the integrator's visible_lights for lamps, lobe_emitter_hit_weight
// and lobe_environment_hit_weight for emitters and the map; a rough dielectric vertex,
// render/dielectric_lighting.h, shares the emitter and map parts through LobeVertex).
// A few lamps are each sampled; many (picks_one_lamp) give one, chosen by the light selector at
// the lobe's normal, and its selection probability is then part of its pdf on both sides of the
// MIS (visible_lights.h, LampChoice). The triangle is chosen as diffuse vertices choose it, and
// its selection probability is part of emitter_pdf(). A constant world is found by the
// continuation ray alone (weight 1): the lobe samples it better than a uniform direction would.
#pragma once

#include "materials/dielectric_lobe.h"
#include "materials/glossy_lobe.h"
#include "materials/scatter.h"
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

// Whether a lobe vertex samples one lamp chosen by the light selector (settings' light_sampling
// resolved to One, as diffuse vertices do: many lamps) instead of every lamp.
inline bool picks_one_lamp(const World& world, const IntegratorSettings& settings) {
  return settings.light_sampling == LightSampling::One && world.lights.size() > 1;
}

// A vertex with a lobe, as the emitter and map samples see it: a glossy lobe (one side, above
// the true surface) or a rough dielectric's (both sides; a direction below leaves by refraction).
// Or Cycles' closures side by side (a Scatter::Kind::Mixture, materials/closure_mixture.h): one
// side, evaluated whole with its mixed pdf.
struct LobeVertex {
  const GlossyLobe* glossy = nullptr;          // exactly one of the three
  const DielectricLobe* dielectric = nullptr;  // (materials/dielectric_lobe.h)
  Vec3 p{0.0f};                                // the hit point
  Vec3 ng{0.0f};                               // the geometric normal on wo's side
  Vec3 above{0.0f}, below{0.0f};               // the shadow rays' origins on each side
  TriangleRef self;                            // the triangle hit: the shadow rays leave it
  const Scatter* mixture = nullptr;
  // The normal the light tree weighs emitters by: the glossy lobe's (the mixture's shading
  // normal); 0 (none) for a dielectric, which takes light from both sides.
  Vec3 tree_normal() const { return glossy ? glossy->frame.n : mixture ? mixture->second_glossy.frame.n : Vec3(0.0f); }
};
// What the lobe makes of a light sample along unit wi: f and the lobe's pdf (f = 0: nothing, the
// direction is on no side the lobe scatters to), |cos| at the shading normal, the shadow ray's
// origin and the kind of ray the lobe's own sample along wi would be (Instance::visibility).
struct LobeAnswer {
  BsdfEval e;
  float cos = 0.0f;
  Vec3 origin{0.0f};
  uint8_t seen_by = 0;
};
LobeAnswer lobe_towards(const LobeVertex& v, const Vec3& wi);

// The lamps' light at the vertex: lamp j draws its sample from Sobol-Owen dimension first_dim + j;
// where picks_one_lamp(), the lamp chosen on dimension pick_dim (1D) at the tree_normal() draws
// from first_dim. Lamps hidden from specular rays or not lighting the receiver set add nothing.
Vec3 lobe_lamp_lighting(const Scene& scene, const LobeVertex& v, uint32_t pixel, uint32_t sample, uint32_t first_dim,
                        uint32_t pick_dim, const IntegratorSettings& settings, uint8_t receiver_set);

// One emissive triangle's light at the vertex (u: the emitter sample's two numbers), in scenes
// with emission; triangles of objects hidden from the ray the lobe would send, or not lighting
// the receiver set, add nothing.
Vec3 lobe_emitter_lighting(const Scene& scene, const LobeVertex& v, const Vec2& u, const IntegratorSettings& settings,
                           uint8_t receiver_set);
// Whether lobe vertices sample the environment map: an active map that glossy or transmission
// rays see (each direction is checked against its own kind).
inline bool samples_environment_at_lobes(const World& world) {
  return world.environment.active() && (world.background_visible_glossy || world.background_visible_transmission);
}
// One direction of the environment map at the vertex, where samples_environment_at_lobes().
Vec3 lobe_environment_lighting(const Scene& scene, const LobeVertex& v, const Vec2& u,
                               const IntegratorSettings& settings);

// All three at the vertex: the lamps (lamp j from dimension light_dim + j, or the one lamp picked on
// emitter_dim - 1), an emitter sample (dimension emitter_dim) and a map sample (emitter_dim + 1)
// where the scene has them.
Vec3 lobe_vertex_lighting(const Scene& scene, const LobeVertex& v, uint32_t pixel, uint32_t sample, uint32_t light_dim,
                          uint32_t emitter_dim, const IntegratorSettings& settings, uint8_t receiver_set);

// Where a lobe vertex sampled emitters and the map from: its point and tree_normal(), for the
// weight of the light its continuation ray finds.
struct LobeOrigin {
  Vec3 p{0.0f};
  Vec3 n{0.0f};
  bool on = false;  // the ray's last vertex was a lobe's (not a delta branch)
};
// The power heuristic's weight of emission the continuation ray of a lobe vertex `from` finds
// (drawn by the lobe with density bsdf_pdf along unit direction wi) against the vertex's own
// emitter sample: on emissive triangle `key` (instance << 32 | triangle) at point `hit_p`.
[[gnu::noinline]] float lobe_emitter_hit_weight(const Scene& scene, const LobeOrigin& from, float bsdf_pdf,
                                                const Vec3& wi, uint64_t key, const Vec3& hit_p);
// ... and of the environment map seen along wi (a ray that left the scene).
[[gnu::noinline]] float lobe_environment_hit_weight(const Scene& scene, float bsdf_pdf, const Vec3& wi);

// A glossy vertex's whole work: its lamps' light (lobe_lamp_lighting, lamp j from dimension
// light_dim + j, or the one lamp picked on emitter_dim - 1), an emitter sample (dimension
// emitter_dim) and a map sample (emitter_dim + 1) where the scene has them, and the continuation
// the lobe draws from dimension lobe_dim: direction, weight f cos / pdf and pdf (0: the path
// ends, the sample left below the geometric surface). Out of line, so the integrator's loop,
// which a Lambert-only scene runs, stays the size it was.
struct GlossyStep {
  Vec3 radiance{0.0f};
  Vec3 wi{0.0f};
  Vec3 weight{0.0f};
  float pdf = 0.0f;
  bool diffuse = false;  // mixture_vertex: the diffuse closure drew wi (the ray only looks for light)
};
[[gnu::noinline]] GlossyStep glossy_vertex(const Scene& scene, const Vec3& p, const Vec3& origin, const Vec3& ng,
                                           TriangleRef self, const GlossyLobe& lobe, uint32_t pixel, uint32_t sample,
                                           uint32_t light_dim, uint32_t lobe_dim, uint32_t emitter_dim,
                                           const IntegratorSettings& settings, uint8_t receiver_set = 0);

// The same for Cycles' closures side by side (Scatter::Kind::Mixture, materials/closure_mixture.h):
// the light samples evaluate the whole mixture, and the continuation's closure is picked on
// dimension pick_dim (1D) before its direction is drawn from lobe_dim.
[[gnu::noinline]] GlossyStep mixture_vertex(const Scene& scene, const Vec3& p, const Vec3& origin, const Vec3& ng,
                                            TriangleRef self, const Scatter& mixture, uint32_t pixel, uint32_t sample,
                                            uint32_t light_dim, uint32_t lobe_dim, uint32_t pick_dim,
                                            uint32_t emitter_dim, const IntegratorSettings& settings,
                                            uint8_t receiver_set = 0);

}  // namespace toyrt
