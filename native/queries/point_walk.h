// Depth-first walks of a Bvh for point queries: every leaf whose box contains a point (the
// inside test), and the leaves in order of box distance with pruning (the closest point).
#pragma once

#include "accel/bvh.h"

namespace toyrt::queries {

inline bool box_contains(const float* b, const Vec3& p) {
  return p.x >= b[0] && p.y >= b[1] && p.z >= b[2] && p.x <= b[3] && p.y <= b[4] && p.z <= b[5];
}

// leaf(first, count) for each leaf whose closed box contains p; a true return ends the walk.
template <class Leaf>
void walk_containing(const Bvh& bvh, const Vec3& p, Leaf&& leaf) {
  if (bvh.nodes.empty() || !box_contains(bvh.nodes[0].bounds, p)) return;
  uint32_t stack[kMaxBvhDepth + 2];
  int sp = 0;
  stack[sp++] = 0;
  while (sp > 0) {
    const Node& n = bvh.nodes[stack[--sp]];
    if (n.is_leaf()) {
      if (leaf(n.first, n.count)) return;
      continue;
    }
    for (uint32_t c = n.first; c < n.first + 2; ++c)
      if (box_contains(bvh.nodes[c].bounds, p)) stack[sp++] = c;
  }
}

// Branch and bound: box_distance2(node) is a lower bound of the squared distance to anything in
// the node; leaf(first, count, best2) tests primitives and lowers best2. Nearer child first; a
// node no nearer than best2 is skipped (it cannot hold a strictly nearer primitive).
template <class BoxDistance2, class Leaf>
void walk_nearest(const Bvh& bvh, BoxDistance2&& box_distance2, Leaf&& leaf, double& best2) {
  if (bvh.nodes.empty()) return;
  struct Entry {
    uint32_t node;
    double d2;
  };
  Entry stack[kMaxBvhDepth + 2];
  int sp = 0;
  stack[sp++] = {0, box_distance2(bvh.nodes[0])};
  while (sp > 0) {
    const Entry e = stack[--sp];
    if (!(e.d2 < best2)) continue;
    const Node& n = bvh.nodes[e.node];
    if (n.is_leaf()) {
      leaf(n.first, n.count, best2);
      continue;
    }
    const uint32_t l = n.first, r = n.first + 1;
    const double dl = box_distance2(bvh.nodes[l]), dr = box_distance2(bvh.nodes[r]);
    // Push the farther first so the nearer is popped next.
    if (dl <= dr) {
      if (dr < best2) stack[sp++] = {r, dr};
      if (dl < best2) stack[sp++] = {l, dl};
    } else {
      if (dl < best2) stack[sp++] = {l, dl};
      if (dr < best2) stack[sp++] = {r, dr};
    }
  }
}

}  // namespace toyrt::queries
