// Top-down BVH builder with the surface area heuristic evaluated over bins of centroids
// (Wald 2007, "On fast construction of SAH-based bounding volume hierarchies"). Works on any
// primitives given their boxes: triangles for a mesh, instances for the top level, lamps.
#pragma once

#include "accel/bvh.h"

#include <atomic>
#include <stdexcept>

namespace toyrt {

struct BinnedSahConfig {
  int bins = 32;          // candidate split planes per axis are bins - 1
  uint32_t max_leaf = 8;  // ranges larger than this are always split
  // Ranges of at most this many primitives become a leaf with no split search. A mesh sets its
  // block width: tracing tests up to that many triangles in one block, and collapse() makes any
  // subtree that small one leaf, so a split below it is work thrown away. 0: always search.
  uint32_t leaf_without_search = 0;
  // Cost of one node visit relative to one primitive test. 3: leaves are tested eight triangles
  // at a time (triangle_block.h), which makes a triangle cheap next to a node's cache misses;
  // measured on the 1M-triangle benchmark mesh, 3 beat 1 by 15-20 % and 6 by 5-10 %.
  float traversal_cost = 3.0f;
  float intersection_cost = 1.0f;
  // Ranges at least this large are binned and bounded in parallel (and partitioned in place).
  size_t parallel_threshold = 8192;
  // Ranges at least this large build their two subtrees as tasks that idle threads may take. With
  // parallel_threshold here, a 10K-triangle mesh made two tasks at its root, whose SAH split is
  // rarely even, and the second thread idled: 512 made the whole 10K commit on two threads about
  // 8 % faster, and left the 1M one as it was (docs/trace-speed.md, thirty-first session). On one
  // thread no tasks are made: there they only cost (+6 % at 10K).
  size_t task_threshold = 512;
  // Polled at every node: when it reads true the build stops by throwing BuildCancelled, so a
  // user's cancel does not wait for a million-triangle build to finish. Not owned; may be null.
  const std::atomic<bool>* cancel = nullptr;
};

// Thrown by a build (and Scene::commit) that was cancelled through its cancel flag.
struct BuildCancelled : std::runtime_error {
  BuildCancelled() : std::runtime_error("BVH build cancelled") {}
};

// Builds over `count` primitives. Runs on the calling thread's TBB arena, so the caller chooses
// the thread count. The result does not depend on the thread count: nodes are laid out in
// depth-first order after the build. A primitive's centre is its box's (BBox::center).
Bvh build_binned_sah(const BBox* prim_bounds, size_t count, const BinnedSahConfig& config = {});

}  // namespace toyrt
