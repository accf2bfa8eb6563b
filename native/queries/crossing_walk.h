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

// Calls visit(crossing, prim) for each crossing of `ray` (world space; tnear <= t < tfar) with
// the mesh of instance `instance_id`, in traversal order (not sorted).
template <class Visit>
void for_each_crossing_in_instance(const Scene& scene, uint32_t instance_id, const Ray& ray, Visit&& visit) {
  const Instance& inst = scene.instance(instance_id);
  const Mesh& mesh = scene.mesh(inst.mesh);
  Vec3 org = ray.org, dir = ray.dir;
  if (!inst.identity) {
    // The same float transform as the nearest-hit query: the exact model starts from it.
    org = Vec3(inst.to_object * glm::vec4(org, 1.0f));
    dir = glm::mat3(inst.to_object) * dir;
    if (!is_finite(org) || !is_finite(dir) || dir == Vec3(0.0f)) return;
  }
  const double tnear = ray.tnear, tfar = ray.tfar;
  const ExactRay exact{DVec3(org), DVec3(dir)};
  const TriangleBlock* blocks = mesh.blocks().data();
  const auto on_crossing = [&](const Crossing& c, uint32_t prim) {
    if (c.t >= tnear && c.t < tfar) visit(c, prim);
  };
  // The wide BVH and its leaf blocks that tracing walks, every leaf the segment reaches.
  const RayBoxData box_ray = make_ray_box_data(org, dir);
  if (float_filter_usable()) {
    const FloatFilterRay fr = float_filter_ray(exact);
    walk_all_leaves(mesh.wide_bvh(), blocks, box_ray, ray.tnear, ray.tfar, [&](uint32_t first, uint32_t count) {
      const uint32_t end = first + (count + kBlockWidth - 1) / kBlockWidth;
      for (uint32_t k = first; k < end; ++k) block_crossings(exact, fr, blocks[k], on_crossing);
    });
  } else {
    walk_all_leaves(mesh.wide_bvh(), blocks, box_ray, ray.tnear, ray.tfar, [&](uint32_t first, uint32_t count) {
      const uint32_t end = first + (count + kBlockWidth - 1) / kBlockWidth;
      for (uint32_t k = first; k < end; ++k) block_crossings(exact, blocks[k], on_crossing);
    });
  }
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
