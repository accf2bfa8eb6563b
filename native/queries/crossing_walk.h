// Visits every exact crossing (queries/exact_crossing.h) of one ray with a committed scene: the
// top-level BVH gathers the instances the ray reaches, each instance's wide BVH (the one tracing
// walks) its triangle blocks. Nothing is pruned by distance (every crossing is wanted), and the
// slab tests are the conservative ones of tracing (Ize's widening, core/bbox.h), so no box the
// exact test would cross in is skipped.
#pragma once

#include "accel/traverse.h"
#include "queries/all_hits_walk.h"
#include "queries/block_crossing.h"
#include "queries/interleaved_walk.h"
#include "scene/scene.h"

#include <vector>

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
  traverse<false>(top, make_ray_box_data(ray.org, ray.dir, scene.instance_box_pad(ray.org)), ray.tnear, t_max,
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

// Walks in flight at once in for_each_crossing_of_rays: enough that a walk's turn comes after its
// next node or block has arrived from memory, few enough that their states stay in the L1 cache.
#ifndef TOYRT_INTERLEAVED_WALKS
#define TOYRT_INTERLEAVED_WALKS 16
#endif
inline constexpr int kInterleavedWalks = TOYRT_INTERLEAVED_WALKS;
// Meshes whose nodes and blocks take fewer bytes than this are walked one ray at a time: they
// stay in the L2 cache, where no wait is left to hide and switching walks only costs.
#ifndef TOYRT_INTERLEAVE_BYTES
#define TOYRT_INTERLEAVE_BYTES (2u << 20)
#endif
inline constexpr size_t kInterleaveBytes = TOYRT_INTERLEAVE_BYTES;

// The bytes of nodes and blocks a walk of `mesh` reads from.
inline size_t walk_bytes(const Mesh& mesh) {
  return mesh.wide_bvh().nodes.size() * sizeof(WideNode) + mesh.blocks().size() * sizeof(TriangleBlock);
}

// Whether some mesh of `scene` is large enough for for_each_crossing_of_rays to pay.
inline bool interleaving_pays(const Scene& scene) {
  for (uint32_t m = 0; m < scene.mesh_count(); ++m)
    if (walk_bytes(scene.mesh(m)) >= kInterleaveBytes) return true;
  return false;
}

// Calls visit(ray, instance, mesh, prim, crossing) for each crossing of the rays [begin, end) of
// `rays` in [ray.tnear, ray.tfar): the crossings for_each_crossing finds, the walks of the rays
// (one per ray and instance reached) interleaved (queries/interleaved_walk.h), so the crossings
// of different rays come mixed, and each ray's in no particular order. Meshes below
// `interleave_bytes` (walk_bytes) are walked one ray at a time (the tests lower it to 0).
template <class Visit>
void for_each_crossing_of_rays(const Scene& scene, const RayBatch& rays, size_t begin, size_t end, Visit&& visit,
                               size_t interleave_bytes = kInterleaveBytes) {
  struct Job {
    uint32_t ray, instance;
  };
  std::vector<Job> jobs;
  jobs.reserve(end - begin);
  const Bvh& top = scene.top_level();
  for (size_t i = begin; i < end; ++i) {
    const Ray ray = rays.at(i);
    if (!is_valid_ray(ray)) continue;
    float t_max = ray.tfar;
    traverse<false>(top, make_ray_box_data(ray.org, ray.dir, scene.instance_box_pad(ray.org)), ray.tnear, t_max,
                    [&](uint32_t first, uint32_t count, float&) {
                      for (uint32_t k = first; k < first + count; ++k) jobs.push_back({uint32_t(i), top.prim_ids[k]});
                      return false;
                    });
  }
  struct State {
    LeafWalk walk;
    ExactRay exact;
    FloatFilterRay float_ray;
    bool use_float;
    const TriangleBlock* blocks;
    double tnear, tfar;
    uint32_t ray, instance, mesh;
  };
  // The blocks of one leaf, as for_each_crossing_in_instance tests them.
  const auto leaf_crossings = [&](const State& st, uint32_t first, uint32_t count) {
    const auto on_crossing = [&](const Crossing& c, uint32_t prim) {
      if (c.t >= st.tnear && c.t < st.tfar) visit(st.ray, st.instance, st.mesh, prim, c);
    };
    const uint32_t stop = first + (count + kBlockWidth - 1) / kBlockWidth;
    for (uint32_t k = first; k < stop; ++k) {
      if (st.use_float)
        block_crossings(st.exact, st.float_ray, st.blocks[k], on_crossing);
      else
        block_crossings(st.exact, st.blocks[k], on_crossing);
    }
  };
  run_interleaved<kInterleavedWalks, State>(
      jobs.size(),
      [&](size_t j, State& st) {
        const Ray ray = rays.at(jobs[j].ray);
        const uint32_t id = jobs[j].instance;
        Vec3 org, dir;
        if (!object_ray(scene, id, ray, org, dir)) return false;
        st.mesh = scene.instance(id).mesh;
        const Mesh& mesh = scene.mesh(st.mesh);
        st.exact = {DVec3(org), DVec3(dir)};
        st.float_ray = float_filter_ray(st.exact);
        st.use_float = float_filter_usable();
        st.blocks = mesh.blocks().data();
        st.tnear = ray.tnear;
        st.tfar = ray.tfar;
        st.ray = jobs[j].ray;
        st.instance = id;
        const WideBvh& bvh = mesh.wide_bvh();
        const RayBoxData box_ray = make_ray_box_data(org, dir);
        if (bvh.nodes.empty() || walk_bytes(mesh) < interleave_bytes) {
          walk_all_leaves(bvh, st.blocks, box_ray, ray.tnear, ray.tfar, [&](uint32_t first, uint32_t count) {
            leaf_crossings(st, first, count);
            return false;
          });
          return false;
        }
        st.walk.start(bvh, box_ray, ray.tnear, ray.tfar);
        return true;
      },
      [&](State& st) {
        return st.walk.step(st.blocks, [&](uint32_t first, uint32_t count) { leaf_crossings(st, first, count); });
      });
}

}  // namespace toyrt::queries
