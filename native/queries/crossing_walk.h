// Visits every exact crossing (queries/exact_crossing.h) of one ray with a committed scene: the
// top-level BVH gathers the instances the ray reaches, each instance's wide BVH (the one tracing
// walks) its triangle blocks. Nothing is pruned by distance (every crossing is wanted), and the
// slab tests are the conservative ones of tracing (Ize's widening, core/bbox.h), so no box the
// exact test would cross in is skipped.
#pragma once

#include "accel/traverse.h"
#include "queries/all_hits_walk.h"
#include "queries/block_crossing.h"
#include "scene/scene.h"

namespace toyrt::queries {

// Whether the batch query treats `ray` as a ray at all (the rule of Scene::intersect).
inline bool is_valid_ray(const Ray& ray) {
  return is_finite(ray.org) && is_finite(ray.dir) && ray.dir != Vec3(0.0f) && !std::isnan(ray.tnear) &&
         !std::isnan(ray.tfar) && ray.tnear <= ray.tfar;
}

// The ray of a query in the object space of instance `id`, as the exact model sees it: the same
// float transform as the nearest-hit query, then converted to double without rounding. False
// when the transformed ray is degenerate (it then crosses nothing).
inline bool object_ray(const Scene& scene, uint32_t id, const Ray& ray, Vec3& org, Vec3& dir) {
  const Instance& inst = scene.instance(id);
  org = ray.org;
  dir = ray.dir;
  if (inst.identity) return true;
  org = Vec3(inst.to_object * glm::vec4(org, 1.0f));
  dir = glm::mat3(inst.to_object) * dir;
  return is_finite(org) && is_finite(dir) && dir != Vec3(0.0f);
}

// Calls block(exact_ray, float_ray, block) for each triangle block of instance `id`'s mesh in a
// leaf that `ray` (world space) reaches on [tnear, tfar], until it returns true. float_ray is
// null where the float filter cannot run (float_filter_usable).
template <class BlockFn>
void for_each_block_in_instance(const Scene& scene, uint32_t id, const Ray& ray, BlockFn&& block) {
  const Mesh& mesh = scene.mesh(scene.instance(id).mesh);
  Vec3 org, dir;
  if (!object_ray(scene, id, ray, org, dir)) return;
  const ExactRay exact{DVec3(org), DVec3(dir)};
  const FloatFilterRay fr = float_filter_ray(exact);
  const FloatFilterRay* float_ray = float_filter_usable() ? &fr : nullptr;
  const TriangleBlock* blocks = mesh.blocks().data();
  // The wide BVH and its leaf blocks that tracing walks, every leaf the segment reaches.
  walk_all_leaves(mesh.wide_bvh(), blocks, make_ray_box_data(org, dir), ray.tnear, ray.tfar,
                  [&](uint32_t first, uint32_t count) {
                    const uint32_t end = first + (count + kBlockWidth - 1) / kBlockWidth;
                    for (uint32_t k = first; k < end; ++k)
                      if (block(exact, float_ray, blocks[k])) return true;
                    return false;
                  });
}

// Calls visit(crossing, prim) for each crossing of `ray` (world space; tnear <= t < tfar) with
// the mesh of instance `instance_id`, in traversal order (not sorted).
template <class Visit>
void for_each_crossing_in_instance(const Scene& scene, uint32_t instance_id, const Ray& ray, Visit&& visit) {
  const double tnear = ray.tnear, tfar = ray.tfar;
  const auto on_crossing = [&](const Crossing& c, uint32_t prim) {
    if (c.t >= tnear && c.t < tfar) visit(c, prim);
  };
  for_each_block_in_instance(scene, instance_id, ray,
                             [&](const ExactRay& exact, const FloatFilterRay* fr, const TriangleBlock& b) {
                               if (fr)
                                 block_crossings(exact, *fr, b, on_crossing);
                               else
                                 block_crossings(exact, b, on_crossing);
                               return false;
                             });
}

// Calls visit(instance, mesh, prim, crossing) for each crossing of the scene in
// [ray.tnear, ray.tfar), in traversal order (not sorted).
template <class Visit>
void for_each_crossing(const Scene& scene, const Ray& ray, Visit&& visit) {
  if (!is_valid_ray(ray)) return;
  const Bvh& top = scene.top_level();
  float t_max = ray.tfar;
  traverse<false>(top, make_ray_box_data(ray.org, ray.dir), ray.tnear, t_max,
                  [&](uint32_t first, uint32_t count, float&) {
                    for (uint32_t k = first; k < first + count; ++k) {
                      const uint32_t id = top.prim_ids[k];
                      const uint32_t mesh = scene.instance(id).mesh;
                      for_each_crossing_in_instance(
                          scene, id, ray, [&](const Crossing& c, uint32_t prim) { visit(id, mesh, prim, c); });
                    }
                    return false;
                  });
}

}  // namespace toyrt::queries
