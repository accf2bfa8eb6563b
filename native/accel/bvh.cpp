// Measures and checks of a built Bvh: SAH cost, depth and the structural invariants.
#include "accel/bvh.h"

#include <sstream>
#include <utility>

namespace toyrt {

double Bvh::sah_cost(double traversal_cost, double intersection_cost) const {
  if (nodes.empty()) return 0.0;
  const double root_area = nodes[0].bbox().half_area();
  if (root_area <= 0.0) return intersection_cost * (nodes[0].is_leaf() ? nodes[0].count : 0);
  double cost = 0.0;
  for (const Node& n : nodes) {
    const double p = n.bbox().half_area() / root_area;  // probability a random ray visits n
    cost += n.is_leaf() ? p * intersection_cost * n.count : p * traversal_cost;
  }
  return cost;
}

int Bvh::depth() const {
  if (nodes.empty()) return 0;
  int deepest = 0;
  std::vector<std::pair<uint32_t, int>> stack{{0u, 1}};
  while (!stack.empty()) {
    auto [i, d] = stack.back();
    stack.pop_back();
    deepest = std::max(deepest, d);
    if (!nodes[i].is_leaf()) {
      stack.push_back({nodes[i].first, d + 1});
      stack.push_back({nodes[i].first + 1, d + 1});
    }
  }
  return deepest;
}

size_t Bvh::leaf_count() const {
  size_t leaves = 0;
  for (const Node& n : nodes) leaves += n.is_leaf();
  return leaves;
}

std::string Bvh::validate(const BBox* prim_bounds, size_t prim_count) const {
  std::ostringstream err;
  if (nodes.empty()) return prim_ids.empty() ? "" : "no nodes but primitives";
  std::vector<int> seen(prim_count, 0);
  std::vector<uint8_t> reached(nodes.size(), 0);
  std::vector<std::pair<uint32_t, int>> stack{{0u, 1}};
  while (!stack.empty()) {
    auto [i, d] = stack.back();
    stack.pop_back();
    if (i >= nodes.size()) {
      err << "child index " << i << " out of range";
      return err.str();
    }
    if (reached[i]++) {
      err << "node " << i << " reached twice";
      return err.str();
    }
    if (d > kMaxBvhDepth) {
      err << "depth " << d << " exceeds " << kMaxBvhDepth;
      return err.str();
    }
    const Node& n = nodes[i];
    const BBox box = n.bbox();
    if (n.is_leaf()) {
      if (size_t(n.first) + n.count > prim_ids.size()) {
        err << "leaf " << i << " out of range";
        return err.str();
      }
      for (uint32_t k = n.first; k < n.first + n.count; ++k) {
        const uint32_t p = prim_ids[k];
        if (p >= prim_count) {
          err << "primitive id " << p << " out of range";
          return err.str();
        }
        ++seen[p];
        if (!box.contains(prim_bounds[p])) {
          err << "primitive " << p << " outside leaf " << i;
          return err.str();
        }
      }
    } else {
      for (uint32_t c : {n.first, n.first + 1}) {
        if (c >= nodes.size()) {
          err << "child index " << c << " out of range";
          return err.str();
        }
        if (!box.contains(nodes[c].bbox())) {
          err << "child " << c << " outside parent " << i;
          return err.str();
        }
        stack.push_back({c, d + 1});
      }
    }
  }
  for (size_t i = 0; i < nodes.size(); ++i)
    if (!reached[i]) {
      err << "node " << i << " unreachable";
      return err.str();
    }
  for (size_t p = 0; p < prim_count; ++p)
    if (seen[p] != 1) {
      err << "primitive " << p << " in " << seen[p] << " leaves";
      return err.str();
    }
  // A builder's ranges (when it gives them): a leaf's own slots; an interior node's, its two
  // children's side by side (the tree is whole by now, so each child's range is checked too).
  if (!ranges.empty()) {
    if (ranges.size() != nodes.size()) return "ranges: not one per node";
    for (size_t i = 0; i < nodes.size(); ++i) {
      const Node& n = nodes[i];
      const auto [first, count] = ranges[i];
      bool ok;
      if (n.is_leaf()) {
        ok = first == n.first && count == n.count;
      } else {
        const auto l = ranges[n.first], r = ranges[n.first + 1];
        ok = first == std::min(l.first, r.first) && count == l.count + r.count &&
             std::max(l.first, r.first) == first + (l.first < r.first ? l.count : r.count);
      }
      if (!ok) {
        err << "range of node " << i << " is not its subtree's";
        return err.str();
      }
    }
  }
  return "";
}

}  // namespace toyrt
