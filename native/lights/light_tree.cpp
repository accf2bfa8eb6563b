#include "lights/light_tree.h"
#include "lights/mesh_emitters.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace toyrt {
namespace {

// Rounding in the cone arithmetic must not turn a cluster that can reach p into a zero: a bound
// is zero only when it fails by this much, and a bound that passes weighs at least kFloor.
constexpr float kMargin = 1e-4f;
constexpr float kFloor = 1e-4f;
// The receiver bound's share of a cluster's receiver term (cluster_importance).
constexpr float kBoundShare = 0.02f;

// A light's importance(), out of line so that select(), probability() and a leaf's sum all get
// the very same float from the same code (an inlined copy could be contracted into other FMAs).
[[gnu::noinline]] float importance_of(const Light& light, const Vec3& p, const Vec3& n) {
  return light_importance(light, p, n);
}
[[gnu::noinline]] float importance_of(const EmissiveTriangle& triangle, const Vec3& p, const Vec3& n) {
  return importance(triangle, p, n);
}

// cos(max(0, theta - a)) from theta's cosine and sine and a's, a in [0, pi].
float cos_minus_clamped(float cos_t, float sin_t, float cos_a, float sin_a) {
  return cos_t >= cos_a ? 1.0f : cos_t * cos_a + sin_t * sin_a;
}

// The cosine of the half-angle theta_u of the cone from p around `to_centre` (unit) that holds
// the box: the widest of its eight corners (Cycles, kernel/light/tree.h, does the same). Tighter
// than the bounding sphere's for the flat, wide clusters of lights over a floor. Given `hull`
// (points whose convex hull holds every emitting point: a triangle's vertices), the widest of them.
float cos_subtended(const LightTreeNode& c, const Vec3& p, const Vec3& to_centre, const Vec3* hull, int hull_count) {
  // The smallest cosine dot(to_centre, w) / |w| over the points w - p, compared without a square
  // root or a division per point: as c |c| = dot |dot| / |w|^2 (monotonic in c), cross-multiplied.
  // One square root at the end; this loop is most of a cluster's cost.
  float num = 1.0f, den = 1.0f;  // c |c| = num / den, den > 0
  const auto consider = [&](const Vec3& point) {
    const Vec3 w = point - p;
    const float dot = glm::dot(to_centre, w), w2 = glm::dot(w, w);
    const float n = dot * std::fabs(dot);
    if (n * den < num * w2) {
      num = n;
      den = w2;
    }
  };
  if (hull) {
    for (int k = 0; k < hull_count; ++k) consider(hull[k]);
  } else {
    for (int k = 0; k < 8; ++k)
      consider(Vec3((k & 1) ? c.hi.x : c.lo.x, (k & 2) ? c.hi.y : c.lo.y, (k & 4) ? c.hi.z : c.lo.z));
  }
  if (!(den > 0.0f)) return -1.0f;  // p on a corner: no angle is bounded
  const float cos_u = std::copysign(std::sqrt(std::fabs(num) / den), num);
  return std::clamp(cos_u, -1.0f, 1.0f);
}

}  // namespace

// The cluster's importance at p with normal n (n = 0: no receiver cosine): power / distance^2,
// times the emitter's cosine bound (theta' = theta - theta_o - theta_u against theta_e, Conty
// Estevez and Kulla 2018, eq. 3) and a receiver's cosine, theta_u the half-angle the box subtends
// from p. Zero only where no light in the box can reach p: the box lies wholly below p's tangent
// plane (Cycles' test), every normal turns away, or the receiver's bound cos(theta_i - theta_u)
// is negative, or p is behind every emitter of a one-sided cluster. Inside the box no angle is
// bounded.
float cluster_importance(const LightTreeNode& c, const Vec3& p, const Vec3& n, const Vec3* hull, int hull_count) {
  const Vec3 centre = 0.5f * c.lo + 0.5f * c.hi;
  const Vec3 half = 0.5f * c.hi - 0.5f * c.lo;
  const Vec3 v = p - centre;  // from the cluster to the point
  const float d2 = glm::dot(v, v);
  const float r2 = glm::dot(half, half);
  // The centre's distance, kept above half the box's half-diagonal (Cycles' clamp): it still
  // ranks two large clusters that both hold p, without the singularity at the centre. With the
  // receiver term below, a quarter (the old clamp) measured 1.1x the variance at 1,000 lights,
  // the full half-diagonal 3.4x (bench_lights); the distance to the box itself 5x (every box of
  // lights over a floor reaches down to it, so every cluster looked equally near).
  const float falloff = std::max({d2, 0.25f * r2, 1e-12f});
  const float d = std::sqrt(d2);
  const bool has_n = n != Vec3(0.0f);
  const float n_length = has_n ? glm::length(n) : 0.0f;
  if (has_n) {
    // The box's highest point over p's tangent plane: below it, no light in the box reaches p.
    const float reach = glm::dot(glm::abs(n), half) - glm::dot(n, v);
    if (reach < -kMargin * n_length * (d + std::sqrt(r2))) return 0.0f;
  }
  // The emitters' horizon: lights that emit only into the half-space in front of them (theta_e
  // <= pi / 2) and nearly share a normal (theta_o < pi / 2) reach p only if it is in front of
  // some point of the box, by a normal within theta_o of the axis (|m - axis| <= 2 sin(theta_o / 2)).
  // A flat one-sided emitter mesh seen from behind weighs zero here instead of being entered and
  // found dark at every leaf (a dead end: no light chosen).
  // (cos_e of theta_e = pi / 2 in floats is -4e-8: still a hemisphere.)
  if (c.cos_e >= -1e-6f && c.cos_o > 0.0f) {
    const float reach_bound = d + std::sqrt(r2);
    const float front = glm::dot(c.axis, v) + glm::dot(glm::abs(c.axis), half) +
                        std::sqrt(std::max(0.0f, 2.0f * (1.0f - c.cos_o))) * reach_bound;
    if (front < -kMargin * reach_bound) return 0.0f;
  }
  const bool inside =
      p.x >= c.lo.x && p.y >= c.lo.y && p.z >= c.lo.z && p.x <= c.hi.x && p.y <= c.hi.y && p.z <= c.hi.z;
  if (inside || !(d > 0.0f)) return c.power / falloff;
  const float cos_u = cos_subtended(c, p, -v / d, hull, hull_count);
  const float sin_u = std::sqrt(std::max(0.0f, 1.0f - cos_u * cos_u));
  float emit = 1.0f;
  // theta_o + theta_u >= pi (a point light's cluster): some normal faces p whatever the angle.
  const float cos_ou = c.cos_o * cos_u - c.sin_o * sin_u;
  const float sin_ou = c.sin_o * cos_u + c.cos_o * sin_u;
  if (sin_ou > 0.0f || (sin_ou == 0.0f && cos_ou > 0.0f)) {
    const float cos_t = glm::dot(c.axis, v) / d;
    const float sin_t = std::sqrt(std::max(0.0f, 1.0f - cos_t * cos_t));
    const float cos_tp = cos_minus_clamped(cos_t, sin_t, cos_ou, sin_ou);
    if (cos_tp < c.cos_e - kMargin) return 0.0f;  // every normal is turned away from p
    emit = std::max(cos_tp, kFloor);
  }
  float receive = 1.0f;
  if (has_n) {
    const float cos_i = -glm::dot(n, v) / (d * n_length);
    const float sin_i = std::sqrt(std::max(0.0f, 1.0f - cos_i * cos_i));
    const float cos_ip = cos_minus_clamped(cos_i, sin_i, cos_u, sin_u);
    if (cos_ip < -kMargin) return 0.0f;  // the whole box is below p's tangent plane
    // The bound cos(theta_i - theta_u) is near 1 for every wide flat cluster over a floor, however
    // grazing its lights are; the cosine towards the centre ranks them, and the bound's small share
    // keeps the weight positive wherever a light can reach (the centre alone could be below the
    // horizon). 2 % of the bound measured 0.72x the variance of the bound alone at 1,000 lights
    // (bench_lights), 10 % 0.75x.
    receive = kBoundShare * std::max(cos_ip, kFloor) + (1.0f - kBoundShare) * std::max(cos_i, 0.0f);
  }
  return c.power * emit * receive / falloff;
}

namespace {

// ---- the build: binned, by Conty Estevez and Kulla's surface area orientation heuristic.

struct Cone {
  Vec3 axis{0.0f, 0.0f, 1.0f};
  float theta_o = 0.0f, theta_e = 0.0f;
  bool empty = true;
};

float angle_between(const Vec3& a, const Vec3& b) { return std::acos(std::clamp(glm::dot(a, b), -1.0f, 1.0f)); }

// The smallest cone (of this construction) holding both: a's axis turned towards b's.
Cone merge(Cone a, const Cone& b) {
  if (b.empty) return a;
  if (a.empty) return b;
  const float theta_e = std::max(a.theta_e, b.theta_e);
  Cone lo = a.theta_o >= b.theta_o ? a : b;  // the wider one
  const Cone& hi = a.theta_o >= b.theta_o ? b : a;
  const float theta_d = angle_between(lo.axis, hi.axis);
  lo.theta_e = theta_e;
  if (std::min(theta_d + hi.theta_o, kPi) <= lo.theta_o) return lo;
  Cone m;
  m.empty = false;
  m.theta_e = theta_e;
  m.theta_o = 0.5f * (lo.theta_o + theta_d + hi.theta_o);
  const Vec3 w = hi.axis - lo.axis * std::cos(theta_d);  // towards hi's axis, orthogonal to lo's
  if (m.theta_o >= kPi || glm::dot(w, w) < 1e-12f) {
    m.theta_o = kPi;  // every direction (or opposite axes: no rotation is defined)
    m.axis = lo.axis;
    return m;
  }
  const float turn = m.theta_o - lo.theta_o;
  m.axis = glm::normalize(lo.axis * std::cos(turn) + glm::normalize(w) * std::sin(turn));
  return m;
}

// The solid-angle measure of the directions a cone emits into (Conty Estevez and Kulla, eq. 1).
float orientation_measure(const Cone& c) {
  const float w = std::min(c.theta_o + c.theta_e, kPi);
  const float so = std::sin(c.theta_o), co = std::cos(c.theta_o);
  return 2.0f * kPi * (1.0f - co) +
         0.5f * kPi * (2.0f * w * so - std::cos(c.theta_o - 2.0f * w) - 2.0f * c.theta_o * so + co);
}

struct Cluster {
  BBox box;
  Cone cone;
  float power = 0.0f;
  void add(const Cluster& o) {
    box.extend(o.box);
    cone = merge(cone, o.cone);
    power += o.power;
  }
  // Surface area times orientation measure times power: what a cluster costs the traversal.
  float cost() const {
    if (box.empty()) return 0.0f;
    return power * (box.half_area() + 1e-12f) * orientation_measure(cone);
  }
};

struct Item {
  Cluster c;
  Vec3 centroid;
  uint32_t light;
};

LightTreeNode make_node(const Cluster& c) {
  LightTreeNode node;
  node.lo = c.box.lo;
  node.hi = c.box.hi;
  node.axis = c.cone.axis;
  node.power = c.power;
  const float theta_o = std::min(c.cone.theta_o, kPi);
  node.cos_o = theta_o >= kPi ? -1.0f : std::cos(theta_o);
  node.sin_o = theta_o >= kPi ? 0.0f : std::max(0.0f, std::sin(theta_o));
  // theta_e up to pi: a spot's cone may be wider than a hemisphere.
  node.cos_e = std::cos(std::min(c.cone.theta_e, kPi));
  return node;
}

struct Builder {
  std::vector<LightTreeNode>& nodes;
  std::vector<int32_t>& parent;
  uint32_t leaf_size = 1;
  int max_depth = 0;

  // Where to split items [begin, end): the binned SAOH plane, or the median on the longest axis
  // when no plane separates the centroids (coincident lights) or the tree grows too deep.
  size_t split(std::vector<Item>& items, size_t begin, size_t end, const Cluster& all, int depth) {
    BBox centroids;
    for (size_t i = begin; i < end; ++i) centroids.extend(items[i].centroid);
    const Vec3 extent = centroids.extent();
    const float longest = std::max({extent.x, extent.y, extent.z});
    constexpr int kBins = 12;
    float best_cost = kInfinity;
    int best_axis = -1, best_plane = 0;
    if (longest > 0.0f && depth < LightTree::kMaxDepth / 2) {
      const Vec3 box_extent = all.box.extent();
      const float box_longest = std::max({box_extent.x, box_extent.y, box_extent.z});
      for (int axis = 0; axis < 3; ++axis) {
        if (!(extent[axis] > 0.0f)) continue;
        std::array<Cluster, kBins> bins{};
        const float scale = kBins / extent[axis];
        const auto bin_of = [&](const Item& it) {
          return std::clamp(int((it.centroid[axis] - centroids.lo[axis]) * scale), 0, kBins - 1);
        };
        for (size_t i = begin; i < end; ++i) bins[size_t(bin_of(items[i]))].add(items[i].c);
        std::array<float, kBins> right_cost{};
        std::array<bool, kBins> right_empty{};
        Cluster right;
        for (int b = kBins - 1; b > 0; --b) {
          right.add(bins[size_t(b)]);
          right_cost[size_t(b)] = right.cost();
          right_empty[size_t(b)] = right.box.empty();
        }
        // Thin boxes split across their short axis cost more: the regularisation of the paper.
        const float regular = box_extent[axis] > 0.0f ? box_longest / box_extent[axis] : 1.0f;
        Cluster left;
        for (int b = 0; b < kBins - 1; ++b) {
          left.add(bins[size_t(b)]);
          if (left.box.empty() || right_empty[size_t(b + 1)]) continue;  // not a split
          const float cost = regular * (left.cost() + right_cost[size_t(b + 1)]);
          if (cost < best_cost) {
            best_cost = cost;
            best_axis = axis;
            best_plane = b;
          }
        }
      }
    }
    if (best_axis >= 0) {
      const float scale = kBins / extent[best_axis];
      const auto mid = std::partition(items.begin() + long(begin), items.begin() + long(end), [&](const Item& it) {
        return std::clamp(int((it.centroid[best_axis] - centroids.lo[best_axis]) * scale), 0, kBins - 1) <= best_plane;
      });
      const size_t m = size_t(mid - items.begin());
      if (m > begin && m < end) return m;
    }
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    const size_t m = begin + (end - begin) / 2;
    std::nth_element(items.begin() + long(begin), items.begin() + long(m), items.begin() + long(end),
                     [&](const Item& a, const Item& b) { return a.centroid[axis] < b.centroid[axis]; });
    return m;
  }

  void build(std::vector<Item>& items, size_t begin, size_t end, int32_t node, int depth) {
    max_depth = std::max(max_depth, depth);
    Cluster all;
    for (size_t i = begin; i < end; ++i) all.add(items[i].c);
    nodes[size_t(node)] = make_node(all);
    if (end - begin <= leaf_size) {
      nodes[size_t(node)].child = -1 - int32_t(begin);  // items' order becomes order_
      nodes[size_t(node)].count = uint32_t(end - begin);
      return;
    }
    const size_t m = split(items, begin, end, all, depth);
    const int32_t first = int32_t(nodes.size());
    nodes[size_t(node)].child = first;
    nodes.resize(nodes.size() + 2);
    parent.resize(nodes.size(), node);
    build(items, begin, m, first, depth + 1);
    build(items, m, end, first + 1, depth + 1);
  }
};

}  // namespace

LightTree::LightTree(const std::vector<Light>& lights, uint32_t leaf_size) {
  std::vector<LightBounds> bounds;
  bounds.reserve(lights.size());
  for (const Light& light : lights) bounds.push_back(light_bounds(light));
  build(bounds, leaf_size);
}

LightTree::LightTree(const std::vector<LightBounds>& bounds, uint32_t leaf_size) { build(bounds, leaf_size); }

void LightTree::build(const std::vector<LightBounds>& bounds, uint32_t leaf_size) {
  leaf_of_.assign(bounds.size(), -1);
  std::vector<Item> items;
  items.reserve(bounds.size());
  for (uint32_t i = 0; i < bounds.size(); ++i) {
    const LightBounds& b = bounds[i];
    if (b.distant) {
      distant_.push_back(i);
      continue;
    }
    Item it;
    it.c.box = b.box;
    it.c.cone = Cone{b.axis, b.theta_o, b.theta_e, false};
    it.c.power = b.power;
    it.centroid = b.box.center();
    it.light = i;
    items.push_back(it);
  }
  if (items.empty()) return;
  nodes_.reserve(2 * items.size() - 1);
  nodes_.resize(1);
  parent_.assign(1, -1);
  Builder builder{nodes_, parent_, std::max(leaf_size, 1u)};
  builder.build(items, 0, items.size(), 0, 0);
  depth_ = builder.max_depth;
  // Reserved for leaves of one; larger leaves use a fraction (half the memory at 2 a leaf).
  nodes_.shrink_to_fit();
  parent_.shrink_to_fit();
  order_.resize(items.size());
  for (size_t i = 0; i < items.size(); ++i) order_[i] = items[i].light;
  for (size_t k = 0; k < nodes_.size(); ++k)
    if (nodes_[k].leaf())
      for (uint32_t i = 0; i < nodes_[k].count; ++i) leaf_of_[order_[nodes_[k].first() + i]] = int32_t(k);
}

void LightTree::set_receiver_sets(std::vector<uint64_t> per_light) {
  if (per_light.empty()) {
    sets_.clear();
    node_sets_.clear();
    return;
  }
  if (per_light.size() != leaf_of_.size())
    throw std::invalid_argument("light tree: one receiver-set mask per light expected");
  sets_ = std::move(per_light);
  // Children are stored after their parent (the builder appends them), so one pass from the
  // back sees every child's union before its parent's.
  node_sets_.assign(nodes_.size(), 0);
  for (size_t k = nodes_.size(); k-- > 0;) {
    const LightTreeNode& node = nodes_[k];
    if (node.leaf()) {
      for (uint32_t i = 0; i < node.count; ++i) node_sets_[k] |= sets_[order_[node.first() + i]];
    } else {
      node_sets_[k] = node_sets_[size_t(node.child)] | node_sets_[size_t(node.child) + 1];
    }
  }
}

size_t LightTree::memory_bytes() const {
  return nodes_.capacity() * sizeof(LightTreeNode) + parent_.capacity() * sizeof(int32_t) +
         order_.capacity() * sizeof(uint32_t) + leaf_of_.capacity() * sizeof(int32_t) +
         distant_.capacity() * sizeof(uint32_t) + (sets_.capacity() + node_sets_.capacity()) * sizeof(uint64_t);
}

// Out of line, and the only place the weights are computed, so select() and probability() divide
// the very same floats (an inlined copy could be contracted into different FMAs).
template <class T>
float LightTree::item_weight(const T* items, uint32_t i, const At& at) const {
  if (!sets_.empty() && !in_light_sets(sets_[i], at.set)) return 0.0f;
  return importance_of(items[i], at.p, at.n);
}

template <class T>
[[gnu::noinline]] LightTree::Weights LightTree::top_weights(const T* lights, const At& at) const {
  Weights w{0.0f, 0.0f};
  if (!nodes_.empty()) w.first = weight(lights, 0, at);
  for (uint32_t i : distant_) w.second += item_weight(lights, i, at);
  return w;
}

template <class T>
[[gnu::noinline]] LightTree::Weights LightTree::child_weights(const T* lights, int32_t node, const At& at) const {
  const size_t first = size_t(nodes_[size_t(node)].child);
  return {weight(lights, first, at), weight(lights, first + 1, at)};
}

// A cluster's bound, or a leaf's exact sum, in order_'s order (the pick's running sum repeats it).
template <class T>
[[gnu::noinline]] float LightTree::weight(const T* lights, size_t index, const At& at) const {
  const LightTreeNode& node = nodes_[index];
  if (!node_sets_.empty() && !in_light_sets(node_sets_[index], at.set)) return 0.0f;
  if (!node.leaf()) return cluster_importance(node, at.p, at.n);
  float sum = 0.0f;
  for (uint32_t i = 0; i < node.count; ++i) sum += item_weight(lights, order_[node.first() + i], at);
  return sum;
}

namespace {
// u rescaled into the branch it chose, kept below 1 (rounding could reach it).
float rescale(float u, float lo, float width) { return std::min((u - lo) / width, 0x1.fffffep-1f); }
}  // namespace

// The linear selector's pick among lights ids[0, count), whose importances sum to `total` in this
// order (so the running sum ends at exactly `total`; u * total rounding up to it keeps the last
// candidate), the probability scaled by that of reaching them.
template <class T>
LightSelection LightTree::pick_among(const T* lights, const uint32_t* ids, size_t count, float total, float u,
                                     float scale, const At& at) const {
  LightSelection chosen;
  const float target = u * total;
  float running = 0.0f, before = 0.0f, chosen_w = 0.0f;
  for (size_t i = 0; i < count; ++i) {
    const float w = item_weight(lights, ids[i], at);
    if (w <= 0.0f) continue;
    before = running;
    running += w;
    chosen.index = int32_t(ids[i]);
    chosen.probability = scale * (w / total);
    chosen_w = w;
    if (target < running) break;
  }
  if (chosen_w > 0.0f) chosen.remainder = std::clamp((target - before) / chosen_w, 0.0f, 0x1.fffffep-1f);
  return chosen;
}

template <class T>
LightSelection LightTree::select_in(const T* lights, const At& at, float u) const {
  LightSelection chosen;
  const Weights top = top_weights(lights, at);
  const float total = top.first + top.second;
  if (!(total > 0.0f)) return chosen;
  const float p_tree = top.first / total;
  if (!(u < p_tree)) {
    // A light at infinity, by importance among them.
    return pick_among(lights, distant_.data(), distant_.size(), top.second, rescale(u, p_tree, top.second / total),
                      top.second / total, at);
  }
  u = rescale(u, 0.0f, p_tree);
  float probability = top.first / total;
  int32_t node = 0;
  while (!nodes_[size_t(node)].leaf()) {
    const Weights w = child_weights(lights, node, at);
    const float sum = w.first + w.second;
    if (!(sum > 0.0f)) return chosen;  // a bound above passed, both below fail: nothing here reaches p
    const float p_first = w.first / sum;
    if (u < p_first) {
      u = rescale(u, 0.0f, p_first);
      probability *= w.first / sum;
      node = nodes_[size_t(node)].child;
    } else {
      u = rescale(u, p_first, w.second / sum);
      probability *= w.second / sum;
      node = nodes_[size_t(node)].child + 1;
    }
  }
  const LightTreeNode& leaf = nodes_[size_t(node)];
  return pick_among(lights, order_.data() + leaf.first(), leaf.count, weight(lights, size_t(node), at), u, probability,
                    at);
}

template <class T>
float LightTree::probability_in(const T* lights, const At& at, size_t index) const {
  if (index >= leaf_of_.size()) return 0.0f;
  const Weights top = top_weights(lights, at);
  const float total = top.first + top.second;
  if (!(total > 0.0f)) return 0.0f;
  const int32_t leaf = leaf_of_[index];
  if (leaf < 0) {
    const float w = item_weight(lights, uint32_t(index), at);
    return w > 0.0f ? top.second / total * (w / top.second) : 0.0f;
  }
  // The path root to leaf, then the same products in the same order as select().
  std::array<int32_t, kMaxDepth + 1> path;
  int length = 0;
  for (int32_t k = leaf; k >= 0; k = parent_[size_t(k)]) path[size_t(length++)] = k;
  float probability = top.first / total;
  for (int i = length - 1; i > 0; --i) {
    const int32_t node = path[size_t(i)];
    const Weights w = child_weights(lights, node, at);
    const float sum = w.first + w.second;
    if (!(sum > 0.0f)) return 0.0f;
    probability *= (path[size_t(i - 1)] == nodes_[size_t(node)].child ? w.first : w.second) / sum;
  }
  const float w = item_weight(lights, uint32_t(index), at);
  return w > 0.0f ? probability * (w / weight(lights, size_t(leaf), at)) : 0.0f;
}

LightSelection LightTree::select(const Light* lights, const Vec3& p, const Vec3& n, float u, uint8_t set) const {
  return select_in(lights, At{p, n, set}, u);
}
float LightTree::probability(const Light* lights, const Vec3& p, const Vec3& n, size_t index, uint8_t set) const {
  return probability_in(lights, At{p, n, set}, index);
}
LightSelection LightTree::select(const EmissiveTriangle* triangles, const Vec3& p, const Vec3& n, float u) const {
  return select_in(triangles, At{p, n, 0}, u);
}
float LightTree::probability(const EmissiveTriangle* triangles, const Vec3& p, const Vec3& n, size_t index) const {
  return probability_in(triangles, At{p, n, 0}, index);
}

}  // namespace toyrt
