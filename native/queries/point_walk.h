// Depth-first walks for point queries: every leaf whose box contains a point (the inside test),
// and the leaves in order of box distance with pruning (the closest point). Each comes twice: over
// a binary Bvh (the scene's top level over instances) and over a mesh's WideBvh, whose leaves are
// (first block, triangle count) in the mesh's triangle blocks.
#pragma once

#include "accel/bvh.h"
#include "accel/wide_bvh.h"

namespace toyrt::queries {

inline bool box_contains(const float* b, const Vec3& p) {
  return p.x >= b[0] && p.y >= b[1] && p.z >= b[2] && p.x <= b[3] && p.y <= b[4] && p.z <= b[5];
}

// Slot i's box of a wide node in Node::bounds order (lo.x, lo.y, lo.z, hi.x, hi.y, hi.z).
inline void slot_bounds(const WideNode& n, int i, float* b) {
  for (int k = 0; k < 6; ++k) b[k] = n.bounds[k][i];
}

// Entries a wide walk's stack can hold. A step pops one node and pushes at most kWidth children,
// so while the walk is at wide depth d (root 1) the stack holds at most kWidth - 1 unvisited
// siblings for each of the d - 1 levels above and the kWidth children just pushed:
// (kWidth - 1) * (d - 1) + kWidth = (kWidth - 1) * d + 1. Every wide node opens at least one
// binary level of the tree it was collapsed from, so d <= kMaxBvhDepth.
inline constexpr int kWideWalkStack = (kWidth - 1) * kMaxBvhDepth + 1;

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

// The same over a WideBvh: leaf(first block, triangle count). A tree that is a single leaf has no
// box of its own (no wide node), so its leaf is always handed over.
template <class Leaf>
void walk_containing(const WideBvh& bvh, const Vec3& p, Leaf&& leaf) {
  if (bvh.nodes.empty()) {
    if (bvh.root_leaf_count) (void)leaf(bvh.root_leaf_first, bvh.root_leaf_count);
    return;
  }
  uint32_t stack[kWideWalkStack];  // node indices
  int sp = 0;
  stack[sp++] = 0;
  while (sp > 0) {
    const WideNode& n = bvh.nodes[stack[--sp]];
    for (int i = 0; i < kWidth; ++i) {
      float b[6];
      slot_bounds(n, i, b);
      if (!box_contains(b, p)) continue;  // an unused slot's empty box contains nothing
      if (n.count[i] == 0)
        stack[sp++] = n.child[i];
      else if (leaf(n.child[i], n.count[i]))
        return;
    }
  }
}

// Branch and bound: box_distance2(bounds) (6 floats in Node::bounds order) is a lower bound of the
// squared distance to anything in the box; leaf(first, count, best2) tests primitives and lowers
// best2. Nearer child first; a node no nearer than best2 is skipped (it cannot hold a strictly
// nearer primitive).
template <class BoxDistance2, class Leaf>
void walk_nearest(const Bvh& bvh, BoxDistance2&& box_distance2, Leaf&& leaf, double& best2) {
  if (bvh.nodes.empty()) return;
  struct Entry {
    uint32_t node;
    double d2;
  };
  Entry stack[kMaxBvhDepth + 2];
  int sp = 0;
  stack[sp++] = {0, box_distance2(bvh.nodes[0].bounds)};
  while (sp > 0) {
    const Entry e = stack[--sp];
    if (!(e.d2 < best2)) continue;
    const Node& n = bvh.nodes[e.node];
    if (n.is_leaf()) {
      leaf(n.first, n.count, best2);
      continue;
    }
    const uint32_t l = n.first, r = n.first + 1;
    const double dl = box_distance2(bvh.nodes[l].bounds), dr = box_distance2(bvh.nodes[r].bounds);
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

// The same over a WideBvh, leaf(first block, triangle count, best2): a node's children nearer than
// best2 are stacked farthest first, so the nearest is visited next (equal distances: lower slot
// first), and each is pruned again when popped. The order is fixed by the tree, so the first of
// equally near primitives found, which the caller keeps, is the same on every run and thread count.
template <class BoxDistance2, class Leaf>
void walk_nearest(const WideBvh& bvh, BoxDistance2&& box_distance2, Leaf&& leaf, double& best2) {
  if (bvh.nodes.empty()) {
    // A single leaf has no box: 0 bounds the distance of anything (nothing beats a best of 0).
    if (bvh.root_leaf_count && 0.0 < best2) leaf(bvh.root_leaf_first, bvh.root_leaf_count, best2);
    return;
  }
  struct Entry {
    uint32_t child, count;  // as WideNode's: count 0 is a node
    double d2;
  };
  Entry stack[kWideWalkStack];
  int sp = 0;
  stack[sp++] = {0, 0, 0.0};  // the root has no box of its own; its children are pruned below
  while (sp > 0) {
    const Entry e = stack[--sp];
    if (!(e.d2 < best2)) continue;
    if (e.count) {
      leaf(e.child, e.count, best2);
      continue;
    }
    const WideNode& n = bvh.nodes[e.child];
    Entry near[kWidth];  // the children nearer than best2, by increasing distance
    int m = 0;
    for (int i = 0; i < kWidth; ++i) {
      if (!n.used(i)) continue;
      float b[6];
      slot_bounds(n, i, b);
      const double d2 = box_distance2(b);
      if (!(d2 < best2)) continue;
      int k = m++;
      for (; k > 0 && near[k - 1].d2 > d2; --k) near[k] = near[k - 1];  // insertion: stable on ties
      near[k] = {n.child[i], n.count[i], d2};
    }
    while (m > 0) stack[sp++] = near[--m];
  }
}

}  // namespace toyrt::queries
