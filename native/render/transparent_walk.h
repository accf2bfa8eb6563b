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

// The ray that goes on from `at` (on the surface with normal ng) to where `ray` ends: the same
// direction for a ray to infinity, else towards its end point with tfar 1. tnear > tfar when
// the end is already behind.
Ray continue_through(const Ray& ray, const Vec3& at, const Vec3& ng);

// The product of the transparent weights along `ray`, or 0 when it is blocked; at most `budget`
// transparent surfaces pass. casters_only: a shadow ray (instances that cast shadows), else a
// path ray (every instance).
[[gnu::noinline]] Vec3 transmittance_walk(const Scene& scene, Ray ray, int budget, bool casters_only);

// At a surface with a transparent part: whether the path passes through. The transparent
// closure is drawn on the uniform number u with probability its share of the weights, as Cycles
// draws a closure, and the throughput takes weight / probability of the branch drawn, so both
// branches together are unbiased; the other branch shades the material, weighted by the opacity.
[[gnu::noinline]] bool passes_through(const Scene& scene, const MaterialTransparency& t, const Vec2& uv, float u,
                                      Vec3& throughput);

// The render's shadow query: whether light arrives along `ray`, multiplying `tr` by what the
// surfaces passed let through (left alone without transparency in the scene).
inline bool shadow_passes(const Scene& scene, const Ray& ray, int budget, Vec3& tr) {
  if (!scene.any_transparency()) return !scene.shadowed(ray);
  tr *= transmittance_walk(scene, ray, budget, true);
  return tr != Vec3(0.0f);
}

// The same for a BSDF-sampled ray that looks for the world: every object stops it but cut-outs.
inline bool path_passes(const Scene& scene, const Ray& ray, int budget, Vec3& tr) {
  if (!scene.any_transparency()) return !scene.occluded(ray);
  tr *= transmittance_walk(scene, ray, budget, false);
  return tr != Vec3(0.0f);
}

}  // namespace toyrt
