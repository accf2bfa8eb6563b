// Stack-based traversal of a Bvh, shared by the mesh level (triangles) and the top level
// (instances). The leaf callback decides what a primitive is; a template, so each use compiles
// into its own loop with no indirect calls. Children are visited near first, and a popped node
// whose entry distance is already beyond the nearest hit is skipped.
#pragma once

#include "accel/bvh.h"

namespace toyrt {

// leaf(first, count, tfar&) tests primitives Bvh::prim_ids[first .. first + count), shrinks tfar
// to the nearest hit and returns whether it found one. With AnyHit, the first hit ends the walk.
// Returns whether any leaf reported a hit.
template <bool AnyHit, class LeafFn>
inline bool traverse(const Bvh& bvh, const RayBoxData& ray, float tnear, float& tfar, LeafFn&& leaf) {
  if (bvh.nodes.empty()) return false;
  const Node* nodes = bvh.nodes.data();
  if (intersect_box(ray, nodes[0].bounds, tnear, tfar) == kInfinity) return false;

  struct Entry {
    uint32_t node;
    float tentry;
  };
  Entry stack[kMaxBvhDepth];
  int sp = 0;
  uint32_t current = 0;
  bool found = false;
  for (;;) {
    const Node& n = nodes[current];
    if (n.is_leaf()) {
      if (leaf(n.first, n.count, tfar)) {
        found = true;
        if constexpr (AnyHit) return true;
      }
    } else {
      const uint32_t left = n.first;
      const float dl = intersect_box(ray, nodes[left].bounds, tnear, tfar);
      const float dr = intersect_box(ray, nodes[left + 1].bounds, tnear, tfar);
      if (dl != kInfinity) {
        if (dr != kInfinity) {
          // Both hit: go to the nearer, keep the other for later.
          const bool left_first = dl <= dr;
          stack[sp++] = left_first ? Entry{left + 1, dr} : Entry{left, dl};
          current = left_first ? left : left + 1;
        } else {
          current = left;
        }
        continue;
      }
      if (dr != kInfinity) {
        current = left + 1;
        continue;
      }
    }
    // Pop the next subtree that may still hold a nearer hit.
    for (;;) {
      if (sp == 0) return found;
      const Entry e = stack[--sp];
      if (e.tentry <= tfar) {
        current = e.node;
        break;
      }
    }
  }
}

}  // namespace toyrt
