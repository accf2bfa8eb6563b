// A triangle mesh stored once in object space, with its own BVH; instances refer to it by id.
#pragma once

#include "accel/builder.h"
#include "accel/wide_bvh.h"
#include "core/ray.h"
#include "core/uninitialized_array.h"
#include "geometry/triangle_block.h"

#include <vector>

namespace toyrt {

using Triangle = glm::u32vec3;  // vertex indices

class Mesh {
 public:
  // Validates and takes the data. Throws std::invalid_argument on a non-finite vertex or an index
  // out of range. Degenerate triangles (two equal vertices, or exactly collinear) are kept in
  // the mesh, so triangle indices stay those of the input, but left out of the BVH: no ray can hit
  // a triangle of zero area.
  Mesh(std::vector<Vec3> vertices, std::vector<Triangle> triangles);

  // Builds (or rebuilds) the BVH over the triangles that can be hit with build_wide_bvh()
  // (accel/builder.h: Auto, the LBVH fallback and the cancel flag behave as there); runs on
  // the caller's TBB arena. A cancelled build throws BuildCancelled and leaves the mesh unbuilt.
  void build(BuilderKind kind = BuilderKind::Sah, const BuildConfig& config = {}, BuildStats* stats = nullptr);
  bool built() const { return built_; }

  // Closest hit within [tnear, tfar): shrinks tfar and writes u, v, prim on a hit. ray_checked:
  // the caller has already refused a ray with a non-finite or zero component (Scene does for the
  // world ray, which an identity instance passes on unchanged), so the check is not made twice.
  // skip: a triangle never hit (the one the ray leaves: Ray::self), or kInvalidId.
  bool intersect(const Vec3& org, const Vec3& dir, float tnear, float& tfar, float& u, float& v, int32_t& prim,
                 bool ray_checked = false, int32_t skip = kInvalidId) const;
  // Any hit within [tnear, tfar).
  bool occluded(const Vec3& org, const Vec3& dir, float tnear, float tfar, bool ray_checked = false,
                int32_t skip = kInvalidId) const;

  const std::vector<Vec3>& vertices() const { return vertices_; }
  const std::vector<Triangle>& triangles() const { return triangles_; }
  // The traced form (wide nodes, leaf triangles in blocks): for queries that walk it themselves.
  const WideBvh& wide_bvh() const { return wide_; }
  const std::vector<TriangleBlock, HugePageAllocator<TriangleBlock>>& blocks() const { return blocks_; }
  const BBox& bounds() const { return bounds_; }
  // Bytes held by this mesh (input arrays, BVH and leaf triangles).
  size_t memory_bytes() const;

 private:
  // The builder's input: boxes of the `count` triangles that can be hit (their centres are made
  // by the builders that read them), and each one's triangle index in `valid` (left empty when
  // every triangle can be hit: slot = index).
  struct Prepared {
    UninitializedArray<BBox> boxes;
    UninitializedArray<uint32_t> valid;
    size_t count = 0;
  };
  Prepared prepare();  // also sets bounds_
  // From a builder's wide tree over prepare()'s slots: fill the triangle blocks (slots translated
  // to triangle indices by `valid`) and point the wide leaves at them.
  void finish(WideBuild built, const UninitializedArray<uint32_t>& valid);

  template <bool AnyHit, bool kSkip, bool kOverlapLeaves>
  bool trace(const Vec3& org, const Vec3& dir, float tnear, float& tfar, float& u, float& v, int32_t& prim,
             bool ray_checked, int32_t skip) const;

  std::vector<Vec3> vertices_;
  std::vector<Triangle> triangles_;
  WideBvh wide_;  // the builder's tree in the traced layout
  // The leaves' triangles in blocks of eight, in traversal order: a wide leaf child's `child`
  // is its first block, its `count` the number of triangles (blocks: count / kBlockWidth rounded up).
  std::vector<TriangleBlock, HugePageAllocator<TriangleBlock>> blocks_;  // huge pages: read at random
  BBox bounds_;
  bool built_ = false;
  // The vertex and index arrays' size from which finish() requests a node's vertices before
  // copying them (mesh.cpp): between the 3.2 MB of a 180K-triangle sphere, which lost 3-5 % to it,
  // and the 5.8 MB of a 320K one, which gained 3 %.
  static constexpr size_t kScatteredReadBytes = size_t(4) << 20;

 public:
  // The blocks' size beyond which (about twice the last-level cache of the machines measured)
  // finish() writes them past the caches, the closest-hit walk prefetches each leaf's block, and
  // intersect() takes the walk that visits a stacked node while the nearest leaf's block arrives.
  static constexpr size_t kPrefetchBlockBytes = size_t(16) << 20;
  // The blocks' size beyond which occluded() takes the any-hit walk that keeps one leaf in flight
  // (any_hit_wide<true>). Where most blocks miss even the last level it pays: shadow rays through
  // a 4M-triangle sphere's 200 MB of blocks, unoccluded 3-7 % faster, occluded 2 %. Where the last
  // level (32 MB on the Zen 4 measured) still holds much of them it did not: the 1M sphere's 50 MB,
  // unoccluded unchanged, occluded 6-7 % slower, and the closed room's wall-blocked rays 9-16 %
  // (docs/trace-speed.md, fortieth session).
  static constexpr size_t kLeafInFlightBlockBytes = size_t(128) << 20;

 private:
  bool prefetch_blocks_ = false;  // the blocks exceed kPrefetchBlockBytes (finish())
  bool leaf_in_flight_ = false;   // the blocks exceed kLeafInFlightBlockBytes (finish())
};

}  // namespace toyrt
