#include "accel/wide_bvh.h"

#include "core/parallel.h"

#include <algorithm>
#include <array>
#include <cstdint>
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

// Subtrees of more primitives than this are collapsed as parallel tasks (on an arena of more than
// one thread). Each node's plan and place depend on its subtree alone, so the layout is the same
// whatever the tasks. 32768 left a 10K-triangle mesh's collapse on one thread: 1,024-2,048 made it
// 0.29 -> 0.18 ms on two (docs/trace-speed.md, thirty-first session).
constexpr uint32_t kParallelPrimitives = 2048;

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
using Costs = std::array<float, kWidth>;      // by budget - 1
using Counts = std::array<uint32_t, kWidth>;  // wide nodes, by budget - 1

// What solve() passes up: per budget, the least cost and the wide nodes that answer makes.
struct Solved {
  Costs cost;
  Counts nodes;
};

// A binary node and the prim_ids slots under it. The collapse hands each node's range down from its
// parent instead of looking it up: the LBVH's follow from the split position alone, so its
// collapse reads no range array at all (a cache miss a node when it did).
struct Ref {
  uint32_t node;
  SlotRange range;
};

// The binary trees collapse() reads, behind one interface: root() (with its range), interior(i),
// children(parent) (with their ranges), box(i), and plan_slots() (node ids that can be interior,
// which size the plan array).
//
// A builder's Bvh: children adjacent at `first`, ranges given by the builder or walked.
struct FlatTree {
  const Bvh& bvh;
  const Ranges& ranges;

  Ref root() const { return {0, ranges[0]}; }
  bool interior(uint32_t i) const { return !bvh.nodes[i].is_leaf(); }
  std::pair<Ref, Ref> children(const Ref& parent) const {
    const uint32_t l = bvh.nodes[parent.node].first;
    return {{l, ranges[l]}, {l + 1, ranges[l + 1]}};
  }
  BBox box(uint32_t i) const { return bvh.nodes[i].bbox(); }
  size_t plan_slots() const { return bvh.nodes.size(); }
  [[gnu::always_inline]] void prefetch(uint32_t i) const { __builtin_prefetch(&bvh.nodes[i]); }
};

// The LBVH kernels' radix tree, read where the kernels left it: internal node g (the split
// between sorted leaves g and g + 1) has id g, sorted leaf k has id (n - 1) + k. A node over
// sorted leaves [l, r] split at g has children over [l, g] and [g + 1, r].
struct KarrasTree {
  const LbvhTree& t;

  uint32_t internal() const { return uint32_t(t.leaves - 1); }
  uint32_t id(int32_t child) const { return child >= 0 ? uint32_t(child) : internal() + uint32_t(~child); }
  Ref root() const { return {t.root, {0u, uint32_t(t.leaves)}}; }
  bool interior(uint32_t i) const { return i < internal(); }
  std::pair<Ref, Ref> children(const Ref& parent) const {
    const uint32_t g = parent.node, first = parent.range.first;
    const LbvhNode& n = t.nodes[g];
    return {{id(n.left), {first, g + 1u - first}}, {id(n.right), {g + 1u, first + parent.range.count - 1u - g}}};
  }
  BBox box(uint32_t i) const {
    if (!interior(i)) return t.prim_bounds[t.order[i - internal()]];
    const LbvhNode& n = t.nodes[i];
    return {{n.lo[0], n.lo[1], n.lo[2]}, {n.hi[0], n.hi[1], n.hi[2]}};
  }
  size_t plan_slots() const { return t.leaves - 1; }
  // Starts loading what box() will read. Inlined by force, as every prefetch-only helper: GCC
  // deems a call to a function that only loads and prefetches pure, and drops it (as it did this
  // one, once out of line: docs/trace-speed.md, thirty-fifth session).
  [[gnu::always_inline]] void prefetch(uint32_t i) const {
    if (interior(i))
      __builtin_prefetch(&t.nodes[i]);
    else
      __builtin_prefetch(&t.prim_bounds[t.order[i - internal()]]);
  }
};

// The tree as collapse() sees it: a subtree of at most leaf_size primitives is one leaf.
template <class Tree>
struct CollapsedTree {
  const Tree& tree;
  uint32_t leaf_size;
  uint32_t parallel_above;  // subtrees of more primitives are tasks (kParallelPrimitives, or never)

  bool is_leaf(const Ref& r) const { return !tree.interior(r.node) || r.range.count <= leaf_size; }
};

template <class Tree>
struct Planner : CollapsedTree<Tree> {
  using CollapsedTree<Tree>::tree;
  using CollapsedTree<Tree>::leaf_size;
  using CollapsedTree<Tree>::is_leaf;
  using CollapsedTree<Tree>::parallel_above;
  Plan* plan;       // by binary node; written for interior nodes that are not collapsed leaves
  uint32_t* heads;  // by binary node: the wide nodes of its subtree when it heads a wide node

  // Bottom up: the costs of binary node i in at most 1..kWidth slots (parent_area: its parent's
  // box's half area), and the wide nodes each answer makes. Each node's plan depends on its
  // subtree alone, so the parallel split (by a fixed primitive count) gives the serial plans.
  Solved solve(const Ref& i, float parent_area = kInfinity) const {
    Solved solved;
    Costs& out = solved.cost;
    if (is_leaf(i)) {  // the same in any budget: one collapsed leaf
      const uint32_t blocks = (i.range.count + leaf_size - 1) / leaf_size;
      out.fill(float(kBlockCost) * tree.box(i.node).half_area() * float(blocks));
      solved.nodes.fill(0);
      return solved;
    }
    const auto [l, r] = tree.children(i);
    // The walk is depth first over a tree larger than the caches: the right child's box (read
    // after the whole left subtree) and the left child's are fetched while this node is solved.
    tree.prefetch(l.node);
    tree.prefetch(r.node);
    const float area_i = tree.box(i.node).half_area();
    // A node whose box is its parent's (a link of a chain: see kChainVisitWeight) weighs more as
    // a wide node of its own, so the programme prefers to open it into its parent's slots.
    const float visit =
        float(kWideNodeCost) * area_i * (area_i >= 0.999f * parent_area ? float(kChainVisitWeight) : 1.0f);
    Solved left, right;
    if (i.range.count > parallel_above) {
      tbb::parallel_invoke([&, l = l] { left = solve(l, area_i); }, [&, r = r] { right = solve(r, area_i); });
    } else {
      left = solve(l, area_i);
      right = solve(r, area_i);
    }
    const Costs &left_cost = left.cost, &right_cost = right.cost;
    Plan& p = plan[i.node];
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
    heads[i.node] = 1u + left.nodes[size_t(p.open_left - 1)] + right.nodes[size_t(kWidth - p.open_left - 1)];
    solved.nodes[0] = heads[i.node];
    // More slots: the node opened into its parent (its children take the slots), or the
    // answer for one slot fewer, whichever is cheaper.
    for (int b = 2; b <= kWidth; ++b) {
      if (spread[b] < out[size_t(b - 2)]) {
        out[size_t(b - 1)] = spread[b];
        p.split[b - 1] = uint8_t(spread_left[b] | (b - spread_left[b]) << 4);
        solved.nodes[size_t(b - 1)] =
            left.nodes[size_t(spread_left[b] - 1)] + right.nodes[size_t(b - spread_left[b] - 1)];
      } else {
        out[size_t(b - 1)] = out[size_t(b - 2)];
        p.split[b - 1] = p.split[b - 2];
        solved.nodes[size_t(b - 1)] = solved.nodes[size_t(b - 2)];
      }
    }
    return solved;
  }
};

template <class Tree>
struct Collapser : CollapsedTree<Tree> {
  using CollapsedTree<Tree>::tree;
  using CollapsedTree<Tree>::is_leaf;
  using CollapsedTree<Tree>::parallel_above;
  const Plan* plan;       // null: the greedy collapse
  const uint32_t* heads;  // as Planner::heads (the greedy collapse's from count())

  // The slots binary node i takes with `budget` of them, by its plan.
  void read_out(const Ref& i, int budget, Ref kids[kWidth], int& n) const {
    if (is_leaf(i) || plan[i.node].split[budget - 1] == 0) {
      kids[n++] = i;
      return;
    }
    const auto [l, r] = tree.children(i);
    read_out(l, plan[i.node].split[budget - 1] & 15, kids, n);
    read_out(r, plan[i.node].split[budget - 1] >> 4, kids, n);
  }

  // The wide node for binary interior node `binary`: the slots of its plan, or (greedy) the
  // binary node's two children, then the largest (by surface area) interior one opened until
  // kWidth are held. Leaf slots are final; an interior slot's child field holds its binary node
  // until the caller places it.
  int gather(const Ref& binary, WideNode& node, Ref kids[kWidth]) const {
    const auto [left, right] = tree.children(binary);
    int n = 0;
    if (plan) {
      read_out(left, plan[binary.node].open_left, kids, n);
      read_out(right, kWidth - plan[binary.node].open_left, kids, n);
    } else {
      kids[n++] = left;
      kids[n++] = right;
      while (n < kWidth) {
        int best = -1;
        float best_area = -1.0f;
        for (int i = 0; i < n; ++i) {
          const float area = tree.box(kids[i].node).half_area();
          if (!is_leaf(kids[i]) && area > best_area) {
            best = i;
            best_area = area;
          }
        }
        if (best < 0) break;
        const auto [l, r] = tree.children(kids[best]);
        kids[best] = l;
        kids[n++] = r;
      }
    }
    // Children in any_hit_order.
    BBox unordered[kWidth], boxes[kWidth];
    Ref found[kWidth];
    for (int i = 0; i < n; ++i) {
      found[i] = kids[i];
      unordered[i] = tree.box(kids[i].node);
    }
    int order[kWidth];
    any_hit_order(unordered, n, order);
    for (int i = 0; i < n; ++i) {
      kids[i] = found[order[i]];
      boxes[i] = unordered[order[i]];
    }
    for (int a = 0; a < 3; ++a)
      for (int i = 0; i < kWidth; ++i) {
        node.bounds[a][i] = kInfinity;
        node.bounds[a + 3][i] = -kInfinity;
      }
    for (int i = 0; i < kWidth; ++i) node.child[i] = node.count[i] = 0;
    for (int i = 0; i < n; ++i) {
      node.set_box(i, boxes[i]);
      if (is_leaf(kids[i])) {
        node.child[i] = kids[i].range.first;
        node.count[i] = kids[i].range.count;
      }
    }
    return n;
  }

  // The greedy collapse's heads[]: the wide nodes under each node that heads one, by a dry run.
  uint32_t count(const Ref& binary, uint32_t* heads_out) const {
    WideNode node;
    Ref kids[kWidth];
    const int n = gather(binary, node, kids);
    uint32_t total = 1;
    for (int i = 0; i < n; ++i)
      if (!is_leaf(kids[i])) total += count(kids[i], heads_out);
    return heads_out[binary.node] = total;
  }

  // Writes the wide node headed by binary node `binary` at out[index], its interior children's
  // nodes side by side from out[first] (one node's children are read together), and each child's
  // subtree after them, in slot order: a depth-first layout. heads[] sizes every subtree
  // beforehand, so each lands straight in its place, and large children's subtrees are written in
  // parallel with the layout of a serial walk (no per-task arrays, copies or regrowth).
  void place(const Ref& binary, size_t index, size_t first, WideNode* out) const {
    WideNode node;
    Ref kids[kWidth], interior[kWidth];
    size_t start[kWidth];
    const int n = gather(binary, node, kids);
    int m = 0;
    for (int i = 0; i < n; ++i)
      if (!is_leaf(kids[i])) {
        node.child[i] = uint32_t(first + size_t(m));
        interior[m++] = kids[i];
      }
    out[index] = node;
    size_t next = first + size_t(m);
    bool large[kWidth];
    int large_count = 0;
    for (int j = 0; j < m; ++j) {
      start[j] = next;
      next += heads[interior[j].node] - 1u;
      large_count += large[j] = interior[j].range.count > parallel_above;
    }
    auto child = [&](int j) { place(interior[j], first + size_t(j), start[j], out); };
    const bool parallel = large_count > 1;
    if (parallel)
      tbb::parallel_for(0, m, [&](int j) {
        if (large[j]) child(j);
      });
    for (int j = 0; j < m; ++j)
      if (!(parallel && large[j])) child(j);
  }
};

template <class Tree>
WideBvh collapse_tree(const Tree& tree, uint32_t leaf_size, CollapseMethod method) {
  WideBvh wide;
  leaf_size = std::max(leaf_size, 1u);
  // On one thread tasks only cost.
  const uint32_t parallel_above = several_threads() ? kParallelPrimitives : UINT32_MAX;
  const CollapsedTree<Tree> collapsed{tree, leaf_size, parallel_above};
  const Ref root = tree.root();
  if (collapsed.is_leaf(root)) {
    wide.root_leaf_first = root.range.first;
    wide.root_leaf_count = root.range.count;
    return wide;
  }
  // Not zeroed: only the entries of interior nodes are written, and only they are read.
  std::unique_ptr<Plan[]> plans;
  std::unique_ptr<uint32_t[]> heads(new uint32_t[tree.plan_slots()]);
  if (method == CollapseMethod::Sah) {
    plans.reset(new Plan[tree.plan_slots()]);
    Planner<Tree>{collapsed, plans.get(), heads.get()}.solve(root);
  }
  const Collapser<Tree> c{collapsed, plans.get(), heads.get()};
  if (!plans) c.count(root, heads.get());
  wide.nodes.resize(heads[root.node]);  // not zeroed (HugePageAllocator): place() writes every node
  c.place(root, 0, 1, wide.nodes.data());
  return wide;
}
}  // namespace

WideBvh collapse(const Bvh& bvh, uint32_t leaf_size, CollapseMethod method) {
  if (bvh.nodes.empty()) return {};
  // The builder's ranges where it wrote them, else the walk's.
  const bool given = bvh.ranges.size() == bvh.nodes.size();
  const Ranges walked = given ? Ranges{} : subtree_ranges(bvh);
  return collapse_tree(FlatTree{bvh, given ? bvh.ranges : walked}, leaf_size, method);
}

WideBvh collapse(const LbvhTree& tree, uint32_t leaf_size, CollapseMethod method) {
  if (tree.leaves < 2) {  // no internal node: at most one leaf
    WideBvh wide;
    wide.root_leaf_count = uint32_t(tree.leaves);
    return wide;
  }
  return collapse_tree(KarrasTree{tree}, leaf_size, method);
}

void any_hit_order(const BBox* boxes, int n, int order[kWidth]) {
  float area[kWidth];
  for (int i = 0; i < n; ++i) {
    const float a = boxes[i].half_area();
    area[i] = a == a ? a : 0.0f;  // a NaN would compare with nothing and leave two slots one place
  }
  // Each slot's place counted without branches: the slots of larger area, and those of equal area
  // that come earlier (a stable sort). An insertion sort's swaps, on areas in no order, were
  // mispredicted as often as not: 5 % of the 1M-triangle LBVH commit.
  for (int i = 0; i < n; ++i) {
    int place = 0;
    for (int j = 0; j < n; ++j) place += int(area[j] > area[i]) | int(area[j] == area[i] && j < i);
    order[place] = i;
  }
}

void sort_slots(WideNode& node) {
  int used[kWidth], order[kWidth];
  BBox boxes[kWidth];
  int n = 0;
  for (int i = 0; i < kWidth; ++i)
    if (node.used(i)) {
      used[n] = i;
      boxes[n++] = node.box(i);
    }
  any_hit_order(boxes, n, order);
  for (int i = 0; i < n; ++i) order[i] = used[order[i]];
  const WideNode in = node;
  for (int i = 0; i < kWidth; ++i) {
    const bool from = i < n;
    const int s = from ? order[i] : 0;
    for (int b = 0; b < 6; ++b) node.bounds[b][i] = from ? in.bounds[b][s] : (b < 3 ? kInfinity : -kInfinity);
    node.child[i] = from ? in.child[s] : 0;
    node.count[i] = from ? in.count[s] : 0;
  }
}

namespace {

struct BottomUp {
  std::vector<WideNode, HugePageAllocator<WideNode>>& nodes;
  const std::function<void(uint32_t)>& leaves;
  const std::function<void()>& task_end;

  void operator()(uint32_t i, int depth) const {
    WideNode& n = nodes[i];
    uint32_t interior[kWidth];
    int m = 0;
    for (int k = 0; k < kWidth; ++k)
      if (n.count[k] == 0 && n.used(k)) interior[m++] = uint32_t(k);
    // Tasks for the subtrees of the top three branching levels (a node with one interior child
    // does not count): up to 512 of them, each of thousands of primitives on the meshes where
    // this matters.
    if (depth < 3 && m > 1) {
      tbb::parallel_for(0, m, [&](int j) {
        (*this)(n.child[interior[j]], depth + 1);
        task_end();
      });
    } else {
      for (int j = 0; j < m; ++j) (*this)(n.child[interior[j]], depth + (m > 1));
    }
    leaves(i);
    for (int j = 0; j < m; ++j) {
      const WideNode& child = nodes[n.child[interior[j]]];
      BBox b;
      for (int k = 0; k < kWidth; ++k)
        if (child.used(k)) b.extend(child.box(k));
      n.set_box(int(interior[j]), b);
    }
    sort_slots(n);
  }
};

}  // namespace

void complete_wide_boxes(WideBvh& bvh, const std::function<void(uint32_t node)>& leaves,
                         const std::function<void()>& task_end) {
  if (!bvh.nodes.empty()) BottomUp{bvh.nodes, leaves, task_end}(0, 0);
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
