#include "render/integrator.h"

#include "geometry/offset_ray.h"
#include "lights/light_selector.h"
#include "render/closure_pick.h"
#include "render/dielectric_lighting.h"
#include "render/glossy_color.h"
#include "render/glossy_lighting.h"
#include "render/normal_mapping.h"
#include "render/transparent_walk.h"
#include "render/visible_lights.h"
#include "sampling/frame.h"
#include "sampling/sobol_owen.h"
#include "sampling/warp.h"

#include <cmath>
#include <limits>
#include <type_traits>

namespace toyrt {
namespace {

// Sample dimensions: 0 is the pixel jitter and the last one (2^32 - 1) the thin lens's (the
// renderer's); each path vertex takes a block.
constexpr uint32_t kDimsPerVertex = 64;
uint32_t vertex_dimension(int depth, uint32_t k) { return 1 + uint32_t(depth) * kDimsPerVertex + k; }

struct SurfaceHit {
  Vec3 p;   // world position, from the barycentrics (more accurate than org + t dir)
  Vec3 ng;  // unit geometric normal, world space
  Vec3 ns;  // unit shading normal, world space
  Vec2 uv{0.0f};
  int32_t material = -1;
  uint8_t receiver_set = 0;                  // the instance's light-linking receiver set (lights/light_linking.h)
  uint64_t light_receivers = kAllLightSets;  // the sets its emission lights, if it emits (Instance)
  TriangleRef self;                          // the triangle hit: the self of the rays that leave it
};

// Out of line on purpose: inlined into trace_from (as GCC chose once nothing else called it) it
// grew the path loop from 4.2 to 6.8 KB and made a Lambert-only render 3.5 % slower.
[[gnu::noinline]] SurfaceHit surface_at(const Scene& scene, const Hit& hit) {
  const Instance& inst = scene.instance(uint32_t(hit.instance));
  const Mesh& mesh = scene.mesh(inst.mesh);
  const Triangle& tri = mesh.triangles()[size_t(hit.prim)];
  const Vec3 p0 = mesh.vertices()[tri.x], p1 = mesh.vertices()[tri.y], p2 = mesh.vertices()[tri.z];
  const float w = 1.0f - hit.u - hit.v;
  SurfaceHit s;
  const Vec3 local = w * p0 + hit.u * p1 + hit.v * p2;
  // Normals transform by the inverse transpose; the inverse is the instance's to_object.
  const glm::mat3 normal_matrix = glm::transpose(glm::mat3(inst.to_object));
  s.p = inst.identity ? local : Vec3(inst.to_world * glm::vec4(local, 1.0f));
  s.ng = glm::normalize(normal_matrix * glm::cross(p1 - p0, p2 - p0));
  s.ns = s.ng;
  const MeshShading& sh = scene.shading(inst.mesh);
  const size_t c = 3 * size_t(hit.prim);
  if (!sh.corner_normals.empty()) {
    const Vec3 n = w * sh.corner_normals[c] + hit.u * sh.corner_normals[c + 1] + hit.v * sh.corner_normals[c + 2];
    const Vec3 world = normal_matrix * n;
    if (glm::dot(world, world) > 0.0f && is_finite(world)) s.ns = glm::normalize(world);
  }
  if (!sh.corner_uvs.empty()) s.uv = w * sh.corner_uvs[c] + hit.u * sh.corner_uvs[c + 1] + hit.v * sh.corner_uvs[c + 2];
  if (!sh.material_ids.empty()) s.material = sh.material_ids[size_t(hit.prim)];
  s.receiver_set = inst.receiver_set;
  s.light_receivers = inst.light_receivers;
  s.self = TriangleRef{hit.prim, hit.instance};
  return s;
}

// The material id of the triangle a hit found; -1 for a mesh without material ids, which renders
// with the default grey (surface_at) and so emits nothing.
int32_t material_of(const Scene& scene, const Hit& hit) {
  const MeshShading& sh = scene.shading(scene.instance(uint32_t(hit.instance)).mesh);
  return sh.material_ids.empty() ? -1 : sh.material_ids[size_t(hit.prim)];
}

// What the out-of-line lighting functions below share with direct_lighting: the point's shadow
// ray origin, its normals, its diffuse BSDF value and its path vertex.
struct DiffusePoint {
  Vec3 origin, ng, ns, f;
  int depth;
  TriangleRef self;  // the triangle the point lies on: its shadow and cosine rays leave it
};

// The diffuse BRDF value towards wi: the point's f (Lambert), or f times Burley's factor (Blender
// 3.x's Principled diffuse, materials/burley_diffuse.h). A template argument, not a run-time
// test, so a Lambert hit runs the code it ran before Burley's existed.
template <bool kBurley>
[[gnu::always_inline]] inline Vec3 diffuse_f(const DiffusePoint& at, const BurleyDiffuse* retro, const Vec3& wi) {
  if constexpr (kBurley)
    return at.f * burley_factor(*retro, wi);
  else
    return at.f;
}

// A cosine-distributed direction around the shading normal, from sample dimension `dim` of the
// point's path vertex; cos is its cosine to ns (the density is cos / pi).
struct CosineDirection {
  Vec3 wi;
  float cos;
};
// Always inline: it is on the constant-background path of every diffuse hit, where the call GCC
// chose once three functions used it measured +0.8 % on a Lambert-only render.
[[gnu::always_inline]] inline CosineDirection cosine_direction(const DiffusePoint& at, uint32_t pixel, uint32_t sample,
                                                               uint32_t dim, const IntegratorSettings& settings) {
  const Vec3 local =
      sample_cosine_hemisphere(sobol_owen_2d(pixel, sample, vertex_dimension(at.depth, dim), settings.seed));
  return {Frame::from_normal(at.ns).to_world(local), local.z};
}

// cos / pdf of a sample drawn with density `pdf`, times its power-heuristic weight against the
// other strategy's density `other` at the same direction (one sample each).
float mis_cos_over_pdf(float cos, float pdf, float other) { return cos * pdf / (pdf * pdf + other * other); }

// The environment map as a light: one sample from the map's distribution and one
// cosine-distributed, combined by the power heuristic, so a bright sun in the map and a uniform
// sky are both found with little noise.
template <bool kBurley>
[[gnu::noinline]] Vec3 environment_lighting(const Scene& scene, const DiffusePoint& at, const BurleyDiffuse* retro,
                                            uint32_t pixel, uint32_t sample, const IntegratorSettings& settings) {
  const Environment& env = scene.world().environment;
  const Texture& image = scene.textures()[size_t(env.texture)];
  Vec3 sum(0.0f);
  const EnvironmentSample es = sample_environment(
      env, image, sobol_owen_2d(pixel, sample, vertex_dimension(at.depth, kDimsPerVertex - 2), settings.seed));
  if (es.pdf > 0.0f) {
    const float cos_s = glm::dot(at.ns, es.wi);
    Vec3 tr(1.0f);
    if (cos_s > 0.0f && glm::dot(at.ng, es.wi) > 0.0f &&
        shadow_passes(scene, Ray{at.origin, 0.0f, es.wi, kInfinity, at.self}, settings.transparent_max_bounces, tr)) {
      sum += diffuse_f<kBurley>(at, retro, es.wi) * es.radiance * tr * mis_cos_over_pdf(cos_s, es.pdf, cos_s * kInvPi);
    }
  }
  // A BSDF-sampled direction is a path ray, not a shadow ray: an object with visible_shadow off
  // still stops it, as Cycles' does (docs/lights.md).
  const CosineDirection c = cosine_direction(at, pixel, sample, kDimsPerVertex - 1, settings);
  Vec3 tr(1.0f);
  if (glm::dot(at.ng, c.wi) > 0.0f && c.cos > 0.0f &&
      path_passes(scene, Ray{at.origin, 0.0f, c.wi, kInfinity, at.self}, settings.transparent_max_bounces, tr,
                  kVisibleDiffuse))
    sum += diffuse_f<kBurley>(at, retro, c.wi) * environment_radiance(env, image, c.wi) * tr *
           mis_cos_over_pdf(c.cos, c.cos * kInvPi, environment_pdf(env, c.wi));
  return sum;
}

// Emissive meshes, by two strategies combined with the power heuristic, as Cycles combines its
// light sampling with the BSDF-sampled ray of the last bounce: a shadow ray to one emissive
// triangle chosen by power, and one cosine ray that collects the emission it hits. The cosine ray wins beside a large
// emitter (a floor under a glowing ball, which the power-chosen triangle rarely finds well) and is the only strategy
// for emitters, or sides of them, that shadow rays do not sample (emission sampling None, Front, Back).
// Light linking of emissive objects: a triangle whose object does not light the receiver's set
// adds nothing (it stays in the selection: the other triangles' estimates keep their mean).
template <bool kBurley>
[[gnu::noinline]] Vec3 emission_lighting(const Scene& scene, const DiffusePoint& at, const BurleyDiffuse* retro,
                                         const Vec3& p, uint8_t receiver, uint32_t pixel, uint32_t sample,
                                         const IntegratorSettings& settings) {
  const MeshEmitters& emitters = scene.emitters();
  Vec3 sum(0.0f);
  if (!emitters.empty()) {
    EmitterPoint where;
    LightSample ls = sample_emitters(
        emitters, p, at.ns, sobol_owen_2d(pixel, sample, vertex_dimension(at.depth, kDimsPerVertex - 3), settings.seed),
        &where);
    if (ls.valid() &&
        !in_light_sets(scene.instance(uint32_t(emitters.keys[where.index] >> 32)).light_receivers, receiver))
      ls.pdf = 0.0f;                                                  // its object does not light this receiver
    else if (ls.valid() && emitters.triangles[where.index].textured)  // its image, where the sample landed
      ls.radiance = scene.emitted_at(emitters.keys[where.index], where.b);
    if (ls.valid()) {
      const float cos_s = glm::dot(at.ns, ls.wi);
      Vec3 tr(1.0f);
      if (cos_s > 0.0f && glm::dot(at.ng, ls.wi) > 0.0f &&
          shadow_passes(scene, Ray{at.origin, 0.0f, ls.point - at.origin, 1.0f, at.self},
                        settings.transparent_max_bounces, tr)) {
        sum +=
            diffuse_f<kBurley>(at, retro, ls.wi) * ls.radiance * tr * mis_cos_over_pdf(cos_s, ls.pdf, cos_s * kInvPi);
      }
    }
  }
  const CosineDirection c = cosine_direction(at, pixel, sample, kDimsPerVertex - 4, settings);
  const Vec3 wi = c.wi;
  if (glm::dot(at.ng, wi) <= 0.0f || c.cos <= 0.0f) return sum;
  Vec3 tr(1.0f);  // a cosine ray is a path ray: it passes cut-outs (render/transparent_walk.h)
  const Hit hit = nearest_past_cut_outs(scene, Ray{at.origin, 0.0f, wi, kInfinity, at.self},
                                        settings.transparent_max_bounces, tr, kVisibleDiffuse);
  const int32_t m = hit.found() ? material_of(scene, hit) : -1;
  if (m < 0 || size_t(m) >= scene.emission().size() || !scene.emission()[size_t(m)].emits()) return sum;
  if (!in_light_sets(scene.instance(uint32_t(hit.instance)).light_receivers, receiver)) return sum;
  const MaterialEmission& e = scene.emission()[size_t(m)];
  const uint64_t key = uint64_t(uint32_t(hit.instance)) << 32 | uint64_t(uint32_t(hit.prim));
  const Vec3 radiance =
      e.texture < 0 ? e.radiance : emitted(e, scene.textures(), scene.emitter_uv(key, Vec2(hit.u, hit.v)));
  // Not among the sampled triangles (emission sampling None): the cosine ray alone finds it.
  const int64_t index = emitters.index_of(key);
  float pl = 0.0f;
  if (index >= 0) {
    const EmissiveTriangle& t = emitters.triangles[size_t(index)];
    pl = emitter_pdf(emitters, p, at.ns, size_t(index), wi, glm::dot(t.p0 + hit.u * t.e1 + hit.v * t.e2 - p, wi));
  }
  return sum + diffuse_f<kBurley>(at, retro, wi) * radiance * tr * mis_cos_over_pdf(c.cos, c.cos * kInvPi, pl);
}

// Light arriving at a diffuse point: one sample per light, or one light chosen by contribution.
// kBurley: the BRDF is f times Burley's factor of *retro (else f; retro unread).
// kCutOuts: the scene has transparent materials (shadow rays walk through them); false compiles
// the any-hit queries alone, so a scene without them runs the code it ran before they existed.
template <bool kBurley, bool kCutOuts>
Vec3 direct_lighting(const Scene& scene, const SurfaceHit& s, const Vec3& ng, const Vec3& ns, const Vec3& f,
                     const BurleyDiffuse* retro, int depth, uint32_t pixel, uint32_t sample,
                     const IntegratorSettings& settings) {
  const World& world = scene.world();
  const Vec3 origin = offset_ray_origin(s.p, ng);
  const DiffusePoint at{origin, ng, ns, f, depth, s.self};
  Vec3 sum(0.0f);
  auto add = [&](size_t index, float select_probability, uint32_t dim) {
    const LightVisibility v = world.light_visibility[index];
    // Light linking: a light that does not light this object adds nothing. The selection below
    // never picks one (Scene::light_receiver_sets); this check serves the loop over every light.
    // Unlinked scenes have full masks and always pass.
    if (!v.diffuse || !in_light_sets(v.receiver_sets, s.receiver_set)) return;
    const LightSample ls =
        sample_light(world.lights[index], s.p,
                     sobol_owen_2d(pixel, sample, vertex_dimension(depth, dim), settings.seed), settings.area_sampling);
    if (!ls.valid()) return;
    const float cos_s = glm::dot(ns, ls.wi);
    if (cos_s <= 0.0f || glm::dot(ng, ls.wi) <= 0.0f) return;  // below the shading or the true surface
    Vec3 tr(1.0f);                                             // what cut-outs let through
    if (v.shadow) {
      // The shadow ray ends where the light sample is: t = 1 with an unnormalised direction; a
      // light at infinity (the sun) leaves the scene along wi.
      const Ray shadow = std::isinf(ls.distance) ? Ray{origin, 0.0f, ls.wi, kInfinity, s.self}
                                                 : Ray{origin, 0.0f, ls.point - origin, 1.0f, s.self};
      if (kCutOuts ? !shadow_passes(scene, shadow, settings.transparent_max_bounces, tr, v.blocker_sets)
                   : scene.shadowed(shadow, v.blocker_sets))
        return;
    }
    sum += diffuse_f<kBurley>(at, retro, ls.wi) * ls.radiance * tr * (cos_s / (ls.pdf * select_probability));
  };
  // The world, emissive meshes: each in a function of its own, out of line, so a scene of lamps
  // and a constant world runs the same small loop as before they existed.
  if (world.background_lights_surfaces && world.environment.active())
    sum += environment_lighting<kBurley>(scene, at, retro, pixel, sample, settings);
  else if (world.background_lights_surfaces && world.background != Vec3(0.0f)) {
    // A constant background: a cosine-distributed direction makes the estimate f L cos / pdf =
    // albedo L when nothing blocks it, exactly. A BSDF-sampled ray: every object stops it.
    const Vec3 wi = cosine_direction(at, pixel, sample, kDimsPerVertex - 1, settings).wi;
    Vec3 tr(1.0f);
    if (glm::dot(ng, wi) > 0.0f &&
        (kCutOuts ? path_passes(scene, Ray{origin, 0.0f, wi, kInfinity, s.self}, settings.transparent_max_bounces, tr,
                                kVisibleDiffuse)
                  : !scene.occluded(Ray{origin, 0.0f, wi, kInfinity, s.self}, kVisibleDiffuse)))
      sum += diffuse_f<kBurley>(at, retro, wi) * world.background * tr * kPi;  // f = albedo / pi
  }
  if (scene.any_emission())
    sum += emission_lighting<kBurley>(scene, at, retro, s.p, s.receiver_set, pixel, sample, settings);
  const std::vector<Light>& lights = world.lights;
  if (settings.light_sampling != LightSampling::One || lights.size() == 1) {
    for (size_t j = 0; j < lights.size(); ++j) add(j, 1.0f, 1 + uint32_t(j));
  } else {
    const LightSelector selector(lights, scene.light_tree(), scene.light_receiver_sets());
    const LightSelection pick = selector.select(
        s.p, ns, sobol_owen_1d(pixel, sample, vertex_dimension(depth, 0), settings.seed), s.receiver_set);
    if (pick.found()) add(size_t(pick.index), pick.probability, 1);
  }
  return sum;
}

// A Burley diffuse point's direct light: out of line, so the Lambert path's loop does not grow.
[[gnu::noinline]] Vec3 burley_direct_lighting(const Scene& scene, const SurfaceHit& s, const Vec3& ng, const Vec3& ns,
                                              const Vec3& f, const BurleyDiffuse& retro, int depth, uint32_t pixel,
                                              uint32_t sample, const IntegratorSettings& settings) {
  return scene.any_transparency()
             ? direct_lighting<true, true>(scene, s, ng, ns, f, &retro, depth, pixel, sample, settings)
             : direct_lighting<true, false>(scene, s, ng, ns, f, &retro, depth, pixel, sample, settings);
}

// The leaf material of a mix slot (materials/material_mix.h), drawn on its own sample dimension;
// a slot that is no mix is its own leaf. Out of line: only scenes with a Mix Shader call it.
[[gnu::noinline]] MixPick pick_mix(const Scene& scene, int32_t material, const Vec2& uv, const Vec3& wo, const Vec3& ns,
                                   bool front, uint32_t pixel, uint32_t sample, int depth,
                                   const IntegratorSettings& settings) {
  const float u = sobol_owen_1d(pixel, sample, vertex_dimension(depth, kDimsPerVertex - 8), settings.seed);
  return pick_mixed(scene.mixes(), scene.textures(), material, MixPoint{uv, wo, ns, !front}, u);
}

// The instances a path ray of this kind sees (Instance::visibility).
uint8_t seen_by(RayKind kind) {
  return kind == RayKind::Camera         ? kVisibleCamera
         : kind == RayKind::Glossy       ? kVisibleGlossy
         : kind == RayKind::Transmission ? kVisibleTransmission
                                         : kVisibleDiffuse;
}

// The kind of ray that leaves a surface along wi, on the side of ng the path came from: a
// reflection (glossy, as Cycles' path flags) or a refraction (transmission).
RayKind kind_towards(const Vec3& wi, const Vec3& ng) {
  return glm::dot(wi, ng) > 0.0f ? RayKind::Glossy : RayKind::Transmission;
}

// The ray's footprint (camera/ray_cone.h), carried only by the loop that reads bump maps: the
// other instantiation takes an empty parameter, which is not passed at all.
struct NoCone {};
template <bool kNormalMaps>
using ConeOf = std::conditional_t<kNormalMaps, RayCone, NoCone>;

// The radiance arriving along `ray`, whose first vertex is path vertex `depth` (0: the camera
// ray), after `first_crossed` transparent surfaces; `first_kind` is the ray's kind for the
// world's visibility; `cone` its footprint (kNormalMaps only). Recursive only where a Fresnel
// surface is split, so at most split_depth levels deep.
// kNormalMaps: some material has a normal map (Scene::any_normal_map); false compiles the loop
// without them, so other scenes run the code they ran before normal maps existed.
template <bool kCutOuts, bool kNormalMaps>
Vec3 trace_from(const Scene& scene, Ray ray, int first_depth, uint32_t pixel, uint32_t sample,
                const IntegratorSettings& path_settings, FirstHit* first = nullptr, int first_crossed = 0,
                RayKind first_kind = RayKind::Camera, uint8_t first_receiver = 0,
                [[maybe_unused]] ConeOf<kNormalMaps> cone = {}) {
  static const Material kDefault = Lambert{};
  const World& world = scene.world();
  const std::vector<Material>& materials = scene.materials();
  Vec3 throughput(1.0f), radiance(0.0f);
  // After a glossy vertex: the density its lobe drew `ray` with (0 otherwise), and whether the
  // ray only looks for light (past max_specular_depth, as Cycles traces the last bounce's ray
  // for the emission it finds and shades nothing there).
  float bsdf_pdf = 0.0f;
  bool light_only = false;
  // After a glossy vertex whose diffuse part Cycles' closure pick shares in (render/closure_pick.h):
  // the throughput for what the next vertex scatters; `throughput` serves the light the ray sees.
  bool picked = false;
  Vec3 picked_throughput(0.0f);
  // The selector a lobe vertex picked its lamp by (picks_one_lamp), for the weight of the lamp
  // its continuation ray finds.
  const LightSelector lamp_selector(world.lights, scene.light_tree(), scene.light_receiver_sets());
  LobeOrigin lobe_from;  // after a glossy or rough dielectric vertex: where it sampled emitters and the map from
  RayKind kind = first_kind;
  uint8_t receiver = first_receiver;             // the light-linking receiver set of the ray's last vertex (0: camera)
  CutOutPath cut(path_settings, first_crossed);  // kCutOuts only (render/transparent_walk.h)
  for (int depth = first_depth;; ++depth) {
    const IntegratorSettings& settings = kCutOuts ? cut.settings() : path_settings;
    const int bounce = kCutOuts ? depth - cut.crossed() : depth;  // crossings are not bounces
    const Hit hit = scene.intersect(ray, seen_by(kind));
    Vec3 lamps(0.0f);  // the lamps this ray sees: the Emission pass's at the camera ray
    if (!world.lights.empty()) {
      const float length = glm::length(ray.dir);
      lamps = visible_lights(
          world, scene.lamp_bvh(), ray.org, ray.dir / length, ray.tnear * length, std::min(hit.t, ray.tfar) * length,
          !hit.found(), bounce == 0 ? uint8_t(kVisibleCamera) : seen_by(kind), settings.area_sampling, bsdf_pdf,
          receiver,
          lobe_from.on && picks_one_lamp(world, settings) ? LampChoice{&lamp_selector, lobe_from.p, lobe_from.n}
                                                          : LampChoice{});
      radiance += throughput * lamps;
    }
    if (!hit.found()) {
      if (first) first->emission = lamps;
      if (!background_visible(world, kind)) break;
      const Environment& env = world.environment;
      const Vec3 seen = env.active()
                            ? environment_radiance(env, scene.textures()[size_t(env.texture)], glm::normalize(ray.dir))
                            : world.background;
      // The map a glossy or rough dielectric vertex also sampled: the lobe's share of it (render/glossy_lighting.h).
      const float w =
          lobe_from.on && env.active() ? lobe_environment_hit_weight(scene, bsdf_pdf, glm::normalize(ray.dir)) : 1.0f;
      radiance += throughput * seen * w;
      if (first) first->environment = seen;  // Cycles' Environment pass: the world seen directly
      break;
    }
    SurfaceHit s = surface_at(scene, hit);
    const Vec3 wo = -glm::normalize(ray.dir);
    [[maybe_unused]] const Vec3 smooth = s.ns;  // before a normal map bends it (render/normal_mapping.h)
    if constexpr (kNormalMaps) {
      // The footprint here; every ray that leaves this hit starts from it, with the same spread
      // (Cycles 3.x: a bounce copies the width and keeps the camera's spread).
      cone.width = cone.at(hit.t * glm::length(ray.dir));
      s.ns = normal_mapped(scene, hit, s.material, wo, s.ng, s.ns, s.uv, cone.width);
    }
    // The geometric normal decides the side; the shading normal is turned to that side.
    const bool front = glm::dot(s.ng, wo) > 0.0f;
    const Vec3 ng = front ? s.ng : -s.ng;
    const Vec3 ns = glm::dot(s.ns, ng) >= 0.0f ? s.ns : -s.ns;
    const Material* m =
        s.material >= 0 && size_t(s.material) < materials.size() ? &materials[size_t(s.material)] : &kDefault;
    if (first) {
      *first = FirstHit{true, s.p, ns, Vec3(0.0f), Vec3(0.0f), lamps, Vec3(0.0f), {wo, s.ng, s.ns, s.uv}};
      first->instance = hit.instance;
      first->material = s.material;
    }
    // A camera or specular ray sees an emitting surface's radiance (both sides, as Cycles' mesh
    // lights); its BSDF (black for a pure Emission shader) still scatters below.
    // Light linking: an emissive object not linked to the receiver set of the ray's last vertex
    // shows no emission there, as Cycles' mesh lights; camera rays see it regardless (unlike a
    // lamp: measured, parity emitter_linking).
    if (scene.any_emission() && s.material >= 0 && size_t(s.material) < materials.size() &&
        (kind == RayKind::Camera || in_light_sets(s.light_receivers, receiver))) {
      const Vec3 glow = emitted(scene.emission()[size_t(s.material)], scene.textures(), s.uv);
      // An emitter a glossy or rough dielectric vertex also sampled: the lobe's share of its light.
      const float w = lobe_from.on ? lobe_emitter_hit_weight(
                                         scene, lobe_from, bsdf_pdf, -wo,
                                         uint64_t(uint32_t(hit.instance)) << 32 | uint64_t(uint32_t(hit.prim)), s.p)
                                   : 1.0f;
      radiance += throughput * glow * w;
      if (first) first->emission += glow;
    }
    if constexpr (kCutOuts) {
      if (cut.ends_here()) break;
      const float u = sobol_owen_1d(pixel, sample, vertex_dimension(depth, kDimsPerVertex - 7), settings.seed);
      if (cut.pass(scene, s.material, s.p, s.ng, s.self, s.uv, u, throughput, ray)) {
        if (first) *first = FirstHit{};  // passes see the first surface the path shades
        continue;
      }
      if (throughput == Vec3(0.0f)) break;
    }
    if (light_only) break;
    lobe_from.on = false;  // set again below by a glossy or rough dielectric vertex
    // A Mix or Add Shader: one of its materials, drawn by weight (materials/material_mix.h), out
    // of line and only in scenes that have one. Its slot's emission, cut-out and normal map were
    // applied above.
    if (scene.any_mix()) [[unlikely]] {
      const MixPick pick = pick_mix(scene, s.material, s.uv, wo, ns, front, pixel, sample, depth, settings);
      if (pick.leaf < 0) break;  // black
      throughput *= pick.weight;
      m = &materials[size_t(pick.leaf)];
    }
    // One generic dispatch per hit, no per-type code: the lambda is instantiated per material
    // type, so for an inline scatter() (Lambert's) the compiler sees the answer's kind as a
    // constant and keeps only the diffuse path, as fast as a hand-written case. It returns
    // whether the path goes on along `ray`. Always inlined: with the glossy cases GCC made the
    // lambda a function of its own, and the Lambert path paid for the call (cachegrind,
    // docs/render.md "A scene pays for what it uses").
    if (picked) [[unlikely]] {
      throughput = picked_throughput;
      picked = false;
    }
    const MaterialContext ctx{&scene.textures(),
                              bounce < settings.split_depth,
                              pixel,
                              sample,
                              vertex_dimension(depth, 0),
                              settings.seed,
                              vertex_dimension(depth, kDimsPerVertex - 6)};
    const bool go_on = std::visit(
        [&](const auto& material) __attribute__((always_inline)) {
          Scatter sc = scatter(material, ShadingPoint{wo, s.ng, s.ns, s.uv}, ctx);
          if constexpr (kNormalMaps)
            shadow_bumps(scene, s.material, sc, glm::dot(smooth, ng) >= 0 ? smooth : -smooth, ns, wo);
          if (sc.kind == Scatter::Kind::Diffuse) {
            if (first) first->diffuse = sc.f * kPi;  // f = albedo / pi
            // f by value: a reference into sc would make the whole answer (its glossy lobe and
            // specular branches, dead here) live in memory across the call.
            const Vec3 f = sc.f;
            if (sc.burley)  // a constant false for Lambert's inline scatter(): folded away
              radiance +=
                  throughput * burley_direct_lighting(scene, s, ng, ns, f, sc.retro, depth, pixel, sample, settings);
            else
              radiance += throughput * direct_lighting<false, kCutOuts>(scene, s, ng, ns, f, nullptr, depth, pixel,
                                                                        sample, settings);
            return false;
          }
          if (sc.kind == Scatter::Kind::Glossy) {
            if (first) {
              first->diffuse = sc.f * kPi;  // the diffuse part beside the lobe (Mix, Add)
              first->glossy = glossy_pass_color(material, sc.glossy);
            }
            if (sc.f != Vec3(0.0f))
              radiance += throughput * (sc.burley ? burley_direct_lighting(scene, s, ng, ns, sc.f, sc.retro, depth,
                                                                           pixel, sample, settings)
                                                  : direct_lighting<false, kCutOuts>(scene, s, ng, ns, sc.f, nullptr,
                                                                                     depth, pixel, sample, settings));
            const Vec3 origin = offset_ray_origin(s.p, ng);
            const GlossyStep g = glossy_vertex(scene, s.p, origin, ng, s.self, sc.glossy, pixel, sample,
                                               vertex_dimension(depth, 1), vertex_dimension(depth, kDimsPerVertex - 5),
                                               vertex_dimension(depth, kDimsPerVertex - 10), settings, s.receiver_set);
            radiance += throughput * g.radiance;
            if (!(g.pdf > 0.0f)) return false;
            if (sc.glossy_pick > 0.0f) {
              // 3.x's base is Burley's diffuse: its value along the lobe's direction.
              const Vec3 f_diffuse = sc.burley ? sc.f * burley_factor(sc.retro, g.wi) : sc.f;
              picked_throughput =
                  throughput * closure_pick_weight(g.weight, g.pdf, f_diffuse, glm::dot(ns, g.wi), sc.glossy_pick);
              picked = true;
            }
            throughput *= g.weight;
            bsdf_pdf = g.pdf;
            lobe_from = LobeOrigin{s.p, sc.glossy.frame.n, true};  // LobeVertex::tree_normal()
            light_only = bounce >= settings.max_specular_depth;
            kind = RayKind::Glossy;
            receiver = s.receiver_set;
            ray = Ray{origin, 0.0f, g.wi, kInfinity, s.self};
            return true;
          }
          if (sc.kind == Scatter::Kind::Mixture) {
            // Cycles' closures side by side (materials/closure_mixture.h): one light sample for all,
            // one closure picked to continue; a diffuse pick's ray only looks for light.
            if (first) {
              first->diffuse = sc.f * kPi;
              first->glossy = glossy_pass_color(material, sc.glossy);
            }
            const Vec3 origin = offset_ray_origin(s.p, ng);
            const GlossyStep g =
                mixture_vertex(scene, s.p, origin, ng, s.self, sc, pixel, sample, vertex_dimension(depth, 1),
                               vertex_dimension(depth, kDimsPerVertex - 5), vertex_dimension(depth, kDimsPerVertex - 6),
                               vertex_dimension(depth, kDimsPerVertex - 10), settings, s.receiver_set);
            radiance += throughput * g.radiance;
            if (!(g.pdf > 0.0f)) return false;
            throughput *= g.weight;
            bsdf_pdf = g.pdf;
            lobe_from = LobeOrigin{s.p, sc.second_glossy.frame.n, true};  // LobeVertex::tree_normal()
            light_only = g.diffuse || bounce >= settings.max_specular_depth;
            kind = g.diffuse ? RayKind::Diffuse : RayKind::Glossy;
            receiver = s.receiver_set;
            ray = Ray{origin, 0.0f, g.wi, kInfinity, s.self};
            return true;
          }
          if (sc.kind == Scatter::Kind::Dielectric) {
            // Lamps on both sides, then a reflection or a transmission: as a glossy vertex, with
            // the side chosen on the lobe-choice dimension.
            const DielectricStep g = dielectric_vertex(
                scene, s.p, ng, s.self, sc.dielectric, pixel, sample, vertex_dimension(depth, 1),
                vertex_dimension(depth, kDimsPerVertex - 5), vertex_dimension(depth, kDimsPerVertex - 6),
                vertex_dimension(depth, kDimsPerVertex - 10), settings, s.receiver_set);
            radiance += throughput * g.radiance;
            if (!(g.pdf > 0.0f)) return false;
            throughput *= g.weight;
            bsdf_pdf = g.pdf;
            lobe_from = LobeOrigin{s.p, Vec3(0.0f), true};  // LobeVertex::tree_normal()
            light_only = bounce >= settings.max_specular_depth;
            kind = kind_towards(g.wi, ng);
            receiver = s.receiver_set;
            ray = Ray{g.origin, 0.0f, g.wi, kInfinity, s.self};
            return true;
          }
          bsdf_pdf = 0.0f;  // a delta branch: no lamp was sampled here
          if (bounce >= settings.max_specular_depth) return false;
          if (sc.kind == Scatter::Kind::Split) {
            for (int b = 0; b < sc.count; ++b) {
              const SpecularSample& branch = sc.branches[b];
              const Ray next{offset_ray_origin(s.p, branch.offset_normal), 0.0f, branch.wi, kInfinity, s.self};
              radiance +=
                  throughput * branch.weight * branch.probability *
                  trace_from<kCutOuts, kNormalMaps>(scene, next, depth + 1, pixel, sample, settings, nullptr,
                                                    cut.crossed(), kind_towards(branch.wi, ng), s.receiver_set, cone);
            }
            return false;
          }
          throughput *= sc.branches[0].weight;
          kind = kind_towards(sc.branches[0].wi, ng);
          receiver = s.receiver_set;
          ray = Ray{offset_ray_origin(s.p, sc.branches[0].offset_normal), 0.0f, sc.branches[0].wi, kInfinity, s.self};
          return true;
        },
        *m);
    first = nullptr;  // passes see the first surface only
    if (!go_on) break;
  }
  return radiance;
}

}  // namespace

Vec3 trace_path(const Scene& scene, const Ray& camera_ray, uint32_t pixel, uint32_t sample,
                const IntegratorSettings& settings, FirstHit* first) {
  const bool cut_outs = scene.any_transparency();
  // The camera ray's footprint, for bumps that difference over it (Scene::any_bump_footprint).
  auto cone = [&] {
    return scene.any_bump_footprint() && settings.camera_cone ? settings.camera_cone->of_ray(camera_ray.dir)
                                                              : RayCone{};
  };
  const Vec3 radiance =
      scene.any_normal_map()
          ? (cut_outs ? trace_from<true, true>(scene, camera_ray, 0, pixel, sample, settings, first, 0, RayKind::Camera,
                                               0, cone())
                      : trace_from<false, true>(scene, camera_ray, 0, pixel, sample, settings, first, 0,
                                                RayKind::Camera, 0, cone()))
          : (cut_outs ? trace_from<true, false>(scene, camera_ray, 0, pixel, sample, settings, first)
                      : trace_from<false, false>(scene, camera_ray, 0, pixel, sample, settings, first));
  // A numerical failure anywhere (it should not happen) must not poison the pixel.
  if (!is_finite(radiance)) return Vec3(0.0f);
  return glm::max(radiance, Vec3(0.0f));
}

}  // namespace toyrt
