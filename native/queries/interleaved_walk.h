// Several rays' all-leaves walks (queries/all_hits_walk.h) advanced in turn, one node or leaf of
// each at a time. On a mesh larger than the caches the single walk waits for memory at every
// step: the child it descends into was stacked (and its lines asked for) just before it is
// read, so one full miss per level is exposed. Here a walk pops its next entry without reading
// it and yields to the other walks; by its next turn the lines asked for when the entry was
// stacked have arrived (software pipelining across independent rays). The leaves reached and
// the tests run are those of walk_all_leaves, so the crossings found are the same.
#pragma once

#include "queries/all_hits_walk.h"

namespace toyrt::queries {

// One ray's walk as a resumable state.
class LeafWalk {
 public:
  // The walk of `ray` on [tnear, tfar] from the root of `bvh` (which has nodes).
  void start(const WideBvh& bvh, const RayBoxData& ray, float tnear, float tfar) {
    nodes_ = bvh.nodes.data();
    ray_ = ray;
    tnear_ = tnear;
    tfar_ = tfar;
    sp_ = 0;
    current_ = {0, 0};
    prefetch_lines(nodes_, sizeof(WideNode));  // read at the walk's first turn
  }

  // Handles the current entry (a node: its reached children are stacked, every line of each
  // asked for; a leaf: leaf(first, count)), then pops the next without reading it. False when the
  // walk is over.
  template <class LeafFn>
  [[gnu::always_inline]] bool step(const TriangleBlock* blocks, LeafFn&& leaf) {
    using namespace simd;
    if (current_.count == 0) {
      const WideNode& n = nodes_[current_.child];
      const vfloat ox = splat(ray_.org.x), oy = splat(ray_.org.y), oz = splat(ray_.org.z);
      const vfloat ix = splat(ray_.inv_dir.x), iy = splat(ray_.inv_dir.y), iz = splat(ray_.inv_dir.z);
      const vfloat tnx = (load(n.bounds[ray_.near[0]]) - ox) * ix, tfx = (load(n.bounds[ray_.far[0]]) - ox) * ix;
      const vfloat tny = (load(n.bounds[ray_.near[1]]) - oy) * iy, tfy = (load(n.bounds[ray_.far[1]]) - oy) * iy;
      const vfloat tnz = (load(n.bounds[ray_.near[2]]) - oz) * iz, tfz = (load(n.bounds[ray_.far[2]]) - oz) * iz;
      vfloat tmin = max_keep(max_keep(max_keep(splat(tnear_), tnx), tny), tnz);
      vfloat tmax = min_keep(min_keep(min_keep(splat(kInfinity), tfx), tfy), tfz);
      // The conservative widening of walk_all_leaves (Ize's, core/bbox.h).
      const vfloat widen = splat(1.0f + 2.0f * gamma(3)), shrink = splat(1.0f - 2.0f * gamma(3));
      if (tnear_ < 0.0f) {
        tmin = tmin < 0.0f ? tmin * widen : tmin;
        tmax = tmax * (tmax < 0.0f ? shrink : widen);
      } else {
        tmax = tmax * widen;
      }
      tmax = min_keep(tmax, splat(tfar_));
      uint32_t mask = mask_of(tmin <= tmax);
      while (mask) {
        const int i = __builtin_ctz(mask);
        mask &= mask - 1;
        const Entry e{n.child[i], n.count[i]};
        if (e.count == 0)
          prefetch_lines(&nodes_[e.child], sizeof(WideNode));
        else
          prefetch_lines(&blocks[e.child], sizeof(TriangleBlock));
        stack_[sp_++] = e;
      }
    } else {
      leaf(current_.child, current_.count);
    }
    if (sp_ == 0) return false;
    current_ = stack_[--sp_];
    return true;
  }

 private:
  struct Entry {
    uint32_t child, count;
  };
  const WideNode* nodes_ = nullptr;
  RayBoxData ray_;
  float tnear_ = 0.0f, tfar_ = 0.0f;
  int sp_ = 0;
  Entry current_{0, 0};
  Entry stack_[(kWidth - 1) * kMaxBvhDepth + 1];
};

// Runs `jobs` walks, kWalks at a time in turn. A State holds a LeafWalk `walk` and whatever the
// caller's steps need; start(job, state) prepares job `job` in it (false: nothing to walk, the job
// is skipped) and step(state) advances it by one step, false when it is over.
template <int kWalks, class State, class Start, class Step>
void run_interleaved(size_t jobs, Start&& start, Step&& step) {
  State states[kWalks];
  int slot[kWalks];  // the states whose walk is in progress, the first `active`
  int active = 0;
  size_t next = 0;
  // Gives state w the next job that has something to walk; false when none is left.
  auto refill = [&](int w) {
    while (next < jobs)
      if (start(next++, states[w])) return true;
    return false;
  };
  for (int w = 0; w < kWalks && refill(w); ++w) slot[active++] = w;
  while (active) {
    for (int s = 0; s < active;) {
      const int w = slot[s];
      if (step(states[w]) || refill(w))
        ++s;
      else
        slot[s] = slot[--active];  // this walk is over and no job is left for it
    }
  }
}

}  // namespace toyrt::queries
