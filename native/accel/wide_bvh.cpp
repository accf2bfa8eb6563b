#include "accel/wide_bvh.h"

#include <algorithm>
#include <utility>

namespace toyrt {

namespace {
// The contiguous range of prim_ids under every node (first, count), by a post-order walk:
// builders lay nodes out in different orders (depth first for SAH, by split position for LBVH).
std::vector<std::pair<uint32_t, uint32_t>> subtree_ranges(const Bvh& bvh) {
  std::vector<std::pair<uint32_t, uint32_t>> range(bvh.nodes.size());
  std::vector<std::pair<uint32_t, bool>> stack{{0u, false}};
  while (!stack.empty()) {
    const auto [i, children_done] = stack.back();
    stack.pop_back();
    const Node& n = bvh.nodes[i];
    if (n.is_leaf()) {
      range[i] = {n.first, n.count};
    } else if (!children_done) {
      stack.push_back({i, true});
      stack.push_back({n.first, false});
      stack.push_back({n.first + 1, false});
    } else {
      const auto l = range[n.first], r = range[n.first + 1];
      range[i] = {std::min(l.first, r.first), l.second + r.second};
    }
  }
  return range;
}
}  // namespace

WideBvh collapse(const Bvh& bvh, uint32_t leaf_size) {
  WideBvh wide;
  if (bvh.nodes.empty()) return wide;
  const auto range = subtree_ranges(bvh);
  auto is_leaf = [&](uint32_t i) { return bvh.nodes[i].is_leaf() || range[i].second <= leaf_size; };
  if (is_leaf(0)) {
    wide.root_leaf_first = range[0].first;
    wide.root_leaf_count = range[0].second;
    return wide;
  }
  wide.nodes.reserve(bvh.nodes.size() / (kWidth - 1) + 1);
  // (binary interior node, wide node it becomes), depth first so subtrees stay together.
  std::vector<std::pair<uint32_t, uint32_t>> work{{0u, 0u}};
  wide.nodes.emplace_back();
  while (!work.empty()) {
    const auto [binary, index] = work.back();
    work.pop_back();
    // Gather children: start from the binary node's two, open interior ones largest first.
    uint32_t kids[kWidth] = {bvh.nodes[binary].first, bvh.nodes[binary].first + 1};
    int n = 2;
    while (n < kWidth) {
      int best = -1;
      float best_area = -1.0f;
      for (int i = 0; i < n; ++i) {
        const Node& c = bvh.nodes[kids[i]];
        if (!is_leaf(kids[i]) && c.bbox().half_area() > best_area) {
          best = i;
          best_area = c.bbox().half_area();
        }
      }
      if (best < 0) break;
      const uint32_t opened = kids[best];
      kids[best] = bvh.nodes[opened].first;
      kids[n++] = bvh.nodes[opened].first + 1;
    }
    // Children by decreasing surface area: the order an any-hit walk visits them in. A large box
    // is the likelier to block a shadow ray (a wall beside a dense model: found at once instead
    // of after the model's subtrees); the closest-hit walk sorts by distance and ignores it.
    // An insertion sort: stable, and no allocation (std::stable_sort takes a temporary buffer,
    // per node).
    for (int i = 1; i < n; ++i) {
      const uint32_t kid = kids[i];
      const float area = bvh.nodes[kid].bbox().half_area();
      int k = i;
      for (; k > 0 && bvh.nodes[kids[k - 1]].bbox().half_area() < area; --k) kids[k] = kids[k - 1];
      kids[k] = kid;
    }
    WideNode node;
    for (int a = 0; a < 3; ++a)
      for (int i = 0; i < kWidth; ++i) {
        node.bounds[a][i] = kInfinity;
        node.bounds[a + 3][i] = -kInfinity;
      }
    for (int i = 0; i < kWidth; ++i) node.child[i] = node.count[i] = 0;
    for (int i = 0; i < n; ++i) {
      const Node& c = bvh.nodes[kids[i]];
      for (int b = 0; b < 6; ++b) node.bounds[b][i] = c.bounds[b];
      if (is_leaf(kids[i])) {
        node.child[i] = range[kids[i]].first;
        node.count[i] = range[kids[i]].second;
      } else {
        node.child[i] = uint32_t(wide.nodes.size());
        wide.nodes.emplace_back();
        work.push_back({kids[i], node.child[i]});
      }
    }
    wide.nodes[index] = node;
  }
  return wide;
}

}  // namespace toyrt
