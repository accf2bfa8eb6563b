// Rays that pass through cut-outs (materials/transparency.h), as Cycles' transparent shadows: a
// shadow ray goes on through each transparent surface it meets, its light multiplied by that
// surface's transparent weight (1 - opacity) x colour, and is blocked by an opaque surface or by
// meeting more transparent surfaces than the path has left of transparent_max_bounces (Cycles
// counts them the same way and then treats the light as blocked). BSDF-sampled rays that only
// look for the world (a diffuse hit's cosine ray towards the background) pass the same way.
//
// Economy: a scene without a transparent material keeps the any-hit queries (Scene::shadowed,
// Scene::occluded); the walk, a closest-hit query per surface crossed, runs only when
// Scene::any_transparency() says some material needs it.
#pragma once

#include "core/math.h"
#include "core/ray.h"
#include "render/render_settings.h"
#include "scene/scene.h"

#include <cstdint>

namespace toyrt {

// The surface a hit found, as the walk and the path's transparent step need it.
struct CrossedSurface {
  Vec3 p{0.0f};   // world position
  Vec3 ng{0.0f};  // unit geometric normal, world space (either side)
  Vec2 uv{0.0f};
  int32_t material = -1;
};
CrossedSurface crossed_surface(const Scene& scene, const Hit& hit);

// The ray that goes on from `at` (on the surface `crossed`, with normal ng) to where `ray` ends:
// the same direction for a ray to infinity, else towards its end point with tfar 1. tnear > tfar
// when the end is already behind. It leaves `crossed` (its self).
Ray continue_through(const Ray& ray, const Vec3& at, const Vec3& ng, TriangleRef crossed);

// The product of the transparent weights along `ray`, or 0 when it is blocked; at most `budget`
// transparent surfaces pass. casters_only: a shadow ray (instances that cast shadows, among the
// blocker sets `blockers` of light linking), else a path ray (every instance).
[[gnu::noinline]] Vec3 transmittance_walk(const Scene& scene, const Ray& ray, int budget, bool casters_only,
                                          uint64_t blockers = kAllLightSets, uint8_t seen_by = kVisibleAll);

// At a surface with a transparent part: whether the path passes through. The transparent
// closure is drawn on the uniform number u with probability its share of the weights, as Cycles
// draws a closure, and the throughput takes weight / probability of the branch drawn, so both
// branches together are unbiased; the other branch shades the material, weighted by the opacity.
[[gnu::noinline]] bool passes_through(const Scene& scene, const MaterialTransparency& t, const Vec2& uv, float u,
                                      Vec3& throughput);

// The nearest hit along `ray` on a surface that is not cut out, multiplying `tr` by what the cut-
// outs before it let through (0 past `budget` of them, or at one that lets nothing through: then
// the hit is the one that blocked); nearest_past_cut_outs is scene.intersect(ray) when the scene
// has no transparent material. casters_only: among the instances that cast shadows (in `blockers`);
// else among those path rays of the kinds `seen_by` see (RayVisibility).
[[gnu::noinline]] Hit walk_to_opaque(const Scene& scene, Ray ray, int budget, Vec3& tr, bool casters_only = false,
                                     uint64_t blockers = kAllLightSets, uint8_t seen_by = kVisibleAll);
inline Hit nearest_past_cut_outs(const Scene& scene, const Ray& ray, int budget, Vec3& tr, uint8_t seen_by) {
  if (!scene.any_transparency()) return scene.intersect(ray, seen_by);
  return walk_to_opaque(scene, ray, budget, tr, false, kAllLightSets, seen_by);
}

// What a path knows of the cut-outs it crossed (the integrator's, for scenes with transparent
// materials): crossings are path vertices but not bounces (as in Cycles), and each lowers what is
// left of transparent_max_bounces, which the path's shadow rays read from settings(); with none
// left, the next surface only emits (Cycles' "terminate on next surface").
class CutOutPath {
 public:
  CutOutPath(const IntegratorSettings& given, int crossed) : given_(&given), crossed_(crossed) {}
  const IntegratorSettings& settings() const { return own_ ? budget_ : *given_; }
  int crossed() const { return crossed_; }
  bool ends_here() const { return end_at_next_surface_; }
  // At a surface of material `material` (p, unit geometric normal ng, uv): whether the path passes
  // through (passes_through on u), then `ray` goes on beyond it and the crossing is counted.
  bool pass(const Scene& scene, int32_t material, const Vec3& p, const Vec3& ng, TriangleRef at, const Vec2& uv,
            float u, Vec3& throughput, Ray& ray) {
    if (material < 0 || size_t(material) >= scene.transparency().size()) return false;
    const MaterialTransparency& t = scene.transparency()[size_t(material)];
    if (!t.transparent() || !passes_through(scene, t, uv, u, throughput)) return false;
    ray = continue_through(ray, p, ng, at);
    ++crossed_;
    if (!own_) {
      budget_ = *given_;
      own_ = true;
    }
    end_at_next_surface_ = --budget_.transparent_max_bounces <= 0;
    return true;
  }

 private:
  const IntegratorSettings* given_;
  IntegratorSettings budget_;
  bool own_ = false;
  int crossed_ = 0;
  bool end_at_next_surface_ = false;
};

// The render's shadow query: whether light arrives along `ray`, multiplying `tr` by what the
// surfaces passed let through (left alone without transparency in the scene). `blockers`: the
// light's blocker sets (light linking; all by default).
inline bool shadow_passes(const Scene& scene, const Ray& ray, int budget, Vec3& tr, uint64_t blockers = kAllLightSets) {
  if (!scene.any_transparency()) return !scene.shadowed(ray, blockers);
  tr *= transmittance_walk(scene, ray, budget, true, blockers);
  return tr != Vec3(0.0f);
}

// The same for a BSDF-sampled ray that looks for the world: every object that rays of the kinds
// `seen_by` see stops it, but cut-outs.
inline bool path_passes(const Scene& scene, const Ray& ray, int budget, Vec3& tr, uint8_t seen_by) {
  if (!scene.any_transparency()) return !scene.occluded(ray, seen_by);
  tr *= transmittance_walk(scene, ray, budget, false, kAllLightSets, seen_by);
  return tr != Vec3(0.0f);
}

}  // namespace toyrt
