#include "accel/wide_bvh.h"

#include <algorithm>
#include <array>
#include <memory>
#include <utility>

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

namespace toyrt {

namespace {
using Ranges = std::vector<SlotRange, HugePageAllocator<SlotRange>>;

// The contiguous range of prim_ids under every node (first, count), by a post-order walk:
// builders lay nodes out in different orders (depth first for SAH, by split position for LBVH).
Ranges subtree_ranges(const Bvh& bvh) {
  Ranges range(bvh.nodes.size());
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
      range[i] = {std::min(l.first, r.first), l.count + r.count};
    }
  }
  return range;
}

// Subtrees of more primitives than this are collapsed as parallel tasks. Fixed, not derived from
// the thread count, so the layout (and every traversal result) is the same on any machine.
constexpr uint32_t kParallelPrimitives = 32768;

// The dynamic programme's decisions for one binary interior node. Budget b = 1..kWidth is index
// b - 1: how the least cost of the subtree in at most b slots of a wide node is reached, as the
// slots given to the left child (low 4 bits) and to the right (high 4); 0: the node takes one
// slot itself, as the wide node that holds its children. `open_left`: the left child's share of
// the kWidth slots of the node's own wide node (the right child's is kWidth minus it). Only the
// decisions are kept (9 bytes a node): the costs pass from children to parent on the stack, as
// the LBVH's 2M binary nodes at 1M triangles made a kept cost table 80 MB of fresh pages.
struct Plan {
  uint8_t split[kWidth];
  uint8_t open_left;
};
using Costs = std::array<float, kWidth>;  // by budget - 1

// The binary tree as collapse() sees it: a subtree of at most leaf_size primitives is one leaf.
struct CollapsedTree {
  const Bvh& bvh;
  const Ranges& range;
  uint32_t leaf_size;

  bool is_leaf(uint32_t i) const { return bvh.nodes[i].is_leaf() || range[i].count <= leaf_size; }
};

struct Planner : CollapsedTree {
  Plan* plan;  // by binary node; written for interior nodes that are not collapsed leaves

  // Bottom up: the costs of binary node i in at most 1..kWidth slots (parent_area: its parent's
  // box's half area). Each node's plan depends on its subtree alone, so the parallel split (by a
  // fixed primitive count) gives the serial plans.
  Costs solve(uint32_t i, float parent_area = kInfinity) const {
    Costs out;
    if (is_leaf(i)) {  // the same in any budget: one collapsed leaf
      const uint32_t blocks = (range[i].count + leaf_size - 1) / leaf_size;
      out.fill(float(kBlockCost) * bvh.nodes[i].bbox().half_area() * float(blocks));
      return out;
    }
    const uint32_t l = bvh.nodes[i].first, r = l + 1;
    const float area_i = bvh.nodes[i].bbox().half_area();
    // A node whose box is its parent's (a link of a chain: see kChainVisitWeight) weighs more as
    // a wide node of its own, so the programme prefers to open it into its parent's slots.
    const float visit =
        float(kWideNodeCost) * area_i * (area_i >= 0.999f * parent_area ? float(kChainVisitWeight) : 1.0f);
    Costs left_cost, right_cost;
    if (range[i].count > kParallelPrimitives) {
      tbb::parallel_invoke([&] { left_cost = solve(l, area_i); }, [&] { right_cost = solve(r, area_i); });
    } else {
      left_cost = solve(l, area_i);
      right_cost = solve(r, area_i);
    }
    Plan& p = plan[i];
    // Distributing b slots between the children, k to the left: the best k for every b.
    float spread[kWidth + 1];
    uint8_t spread_left[kWidth + 1];
    for (int b = 2; b <= kWidth; ++b) {
      spread[b] = kInfinity;
      spread_left[b] = 1;
      for (int k = 1; k < b; ++k) {
        const float c = left_cost[size_t(k - 1)] + right_cost[size_t(b - k - 1)];
        if (c < spread[b]) {
          spread[b] = c;
          spread_left[b] = uint8_t(k);
        }
      }
    }
    // One slot: the node as a wide node of its own, its children spread over kWidth slots.
    p.open_left = spread_left[kWidth];
    out[0] = visit + spread[kWidth];
    p.split[0] = 0;
    // More slots: the node opened into its parent (its children take the slots), or the
    // answer for one slot fewer, whichever is cheaper.
    for (int b = 2; b <= kWidth; ++b) {
      if (spread[b] < out[size_t(b - 2)]) {
        out[size_t(b - 1)] = spread[b];
        p.split[b - 1] = uint8_t(spread_left[b] | (b - spread_left[b]) << 4);
      } else {
        out[size_t(b - 1)] = out[size_t(b - 2)];
        p.split[b - 1] = p.split[b - 2];
      }
    }
    return out;
  }
};

struct Collapser : CollapsedTree {
  using Nodes = std::vector<WideNode, HugePageAllocator<WideNode>>;
  const Plan* plan;  // null: the greedy collapse

  // The slots binary node i takes with `budget` of them, by its plan.
  void read_out(uint32_t i, int budget, uint32_t kids[kWidth], int& n) const {
    if (is_leaf(i) || plan[i].split[budget - 1] == 0) {
      kids[n++] = i;
      return;
    }
    read_out(bvh.nodes[i].first, plan[i].split[budget - 1] & 15, kids, n);
    read_out(bvh.nodes[i].first + 1, plan[i].split[budget - 1] >> 4, kids, n);
  }

  // The wide node for binary interior node `binary`: the slots of its plan, or (greedy) the
  // binary node's two children, then the largest (by surface area) interior one opened until
  // kWidth are held. Leaf slots are final; an interior slot's child field holds its binary node
  // until the caller places it.
  int gather(uint32_t binary, WideNode& node, uint32_t kids[kWidth]) const {
    const uint32_t left = bvh.nodes[binary].first, right = left + 1;
    int n = 0;
    if (plan) {
      read_out(left, plan[binary].open_left, kids, n);
      read_out(right, kWidth - plan[binary].open_left, kids, n);
    } else {
      kids[n++] = left;
      kids[n++] = right;
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
    }
    // Children by decreasing surface area: the order an any-hit walk visits them in. A large box
    // is the likelier to block a shadow ray (a wall beside a dense model: found at once instead
    // of after the model's subtrees); the closest-hit walk sorts by distance and ignores it.
    // An insertion sort: stable, and no allocation.
    for (int i = 1; i < n; ++i) {
      const uint32_t kid = kids[i];
      const float area = bvh.nodes[kid].bbox().half_area();
      int k = i;
      for (; k > 0 && bvh.nodes[kids[k - 1]].bbox().half_area() < area; --k) kids[k] = kids[k - 1];
      kids[k] = kid;
    }
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
        node.count[i] = range[kids[i]].count;
      }
    }
    return n;
  }

  // Writes the wide node of `binary` at out[index] and its whole subtree after out's end: the
  // interior children of a node side by side (one node's children are read together), each
  // child's subtree after them, in slot order. Large children's subtrees are collapsed in
  // parallel into their own arrays and appended in slot order, so the layout is the serial one's.
  void expand(uint32_t binary, size_t index, Nodes& out) const {
    WideNode node;
    uint32_t kids[kWidth];
    const int n = gather(binary, node, kids);
    const size_t first = out.size();
    int interior[kWidth], m = 0;
    for (int i = 0; i < n; ++i)
      if (!is_leaf(kids[i])) {
        node.child[i] = uint32_t(first + size_t(m));
        interior[m++] = i;
      }
    out.resize(first + size_t(m));
    out[index] = node;
    // Each large child's subtree below it (its own node is local[0]), built in parallel.
    Nodes local[kWidth];
    bool large[kWidth] = {};
    int large_count = 0;
    for (int j = 0; j < m; ++j) large_count += large[j] = range[kids[interior[j]]].count > kParallelPrimitives;
    if (large_count > 1) {
      tbb::parallel_for(0, m, [&](int j) {
        if (large[j]) expand_alone(kids[interior[j]], local[j]);
      });
    } else if (large_count == 1) {
      for (int j = 0; j < m; ++j)
        if (large[j]) expand_alone(kids[interior[j]], local[j]);
    }
    for (int j = 0; j < m; ++j) {
      if (!large[j]) {
        expand(kids[interior[j]], first + size_t(j), out);
        continue;
      }
      // local[j][0] takes its slot among its siblings; local[j][1..] goes to the end, its
      // interior child indices moved by where it lands.
      const Nodes& sub = local[j];
      const size_t base = out.size();
      auto moved = [&](WideNode w) {
        for (int i = 0; i < kWidth; ++i)
          if (w.count[i] == 0 && w.used(i)) w.child[i] = uint32_t(base + w.child[i] - 1);
        return w;
      };
      out[first + size_t(j)] = moved(sub[0]);
      out.resize(base + sub.size() - 1);
      for (size_t k = 1; k < sub.size(); ++k) out[base + k - 1] = moved(sub[k]);
    }
  }

  void expand_alone(uint32_t binary, Nodes& out) const {
    out.resize(1);
    expand(binary, 0, out);
  }
};
}  // namespace

WideBvh collapse(const Bvh& bvh, uint32_t leaf_size, CollapseMethod method) {
  WideBvh wide;
  if (bvh.nodes.empty()) return wide;
  // The builder's ranges where it wrote them (the LBVH's: its two million binary nodes at 1M
  // triangles made this walk a tenth of the commit), else the walk's.
  const bool given = bvh.ranges.size() == bvh.nodes.size();
  const Ranges walked = given ? Ranges{} : subtree_ranges(bvh);
  const Ranges& range = given ? bvh.ranges : walked;
  leaf_size = std::max(leaf_size, 1u);
  // Not zeroed: only interior nodes' plans are written, and only they are read.
  std::unique_ptr<Plan[]> plans;
  if (method == CollapseMethod::Sah) {
    plans.reset(new Plan[bvh.nodes.size()]);
    Planner{{bvh, range, leaf_size}, plans.get()}.solve(0);
  }
  const Collapser c{{bvh, range, leaf_size}, plans.get()};
  if (c.is_leaf(0)) {
    wide.root_leaf_first = range[0].first;
    wide.root_leaf_count = range[0].count;
    return wide;
  }
  wide.nodes.reserve(bvh.nodes.size() / (kWidth - 1) + 1);
  c.expand_alone(0, wide.nodes);
  return wide;
}

WideStats wide_stats(const WideBvh& wide, uint32_t block_width) {
  WideStats s;
  block_width = std::max(block_width, 1u);
  auto blocks = [&](uint32_t count) { return double((count + block_width - 1) / block_width); };
  if (wide.nodes.empty()) {
    s.sah_cost = kBlockCost * blocks(wide.root_leaf_count);
    return s;
  }
  BBox root;
  for (int i = 0; i < kWidth; ++i)
    if (wide.nodes[0].used(i)) root.extend(wide.nodes[0].box(i));
  const double root_area = root.half_area();
  size_t children = 0;
  double cost = kWideNodeCost;  // the root, visited by every ray
  for (const WideNode& n : wide.nodes)
    for (int i = 0; i < kWidth; ++i) {
      if (!n.used(i)) continue;
      ++children;
      const double p = root_area > 0.0 ? n.box(i).half_area() / root_area : 1.0;
      cost += p * (n.count[i] ? kBlockCost * blocks(n.count[i]) : kWideNodeCost);
    }
  s.nodes = wide.nodes.size();
  s.children_per_node = double(children) / double(s.nodes);
  s.sah_cost = cost;
  return s;
}

}  // namespace toyrt
