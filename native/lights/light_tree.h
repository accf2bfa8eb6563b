// A bounding hierarchy over the scene's lights that picks one light per shading point with a
// probability that follows its expected contribution there, in O(log lights) instead of the
// linear selector's two passes over all of them (Conty Estevez and Kulla 2018, "Importance
// Sampling of Many Lights with Adaptive Tree Splitting", without the splitting: one light per
// call). Each node bounds a cluster: a box, an orientation cone (axis, theta_o, theta_e) and the
// cluster's power. Traversal goes down one child at a time, choosing between the two children by
// their importance at (p, n); the probability of a light is the product of the branch
// probabilities along its root-to-leaf path, and probability() recomputes that product along the
// stored path, so it equals what select() returned bit for bit.
//
// Unbiased because a cluster's importance is zero only where no light in it can reach (p, n) (the
// whole cone faces away from p, or the whole box is below p's tangent plane); elsewhere it is a
// positive estimate of the cluster's contribution (not a bound: see cluster_importance). A leaf
// holds up to kLeafSize lights and weighs them by the sum of their own importance(), exact where
// an estimate is coarsest (the nearest lights); the pick inside it is the linear selector's.
// Lights at infinity (suns) have no box: they are chosen among themselves by importance(),
// against the tree's root.
//
// The same tree serves the scene's emissive triangles (lights/mesh_emitters.h): built from their
// LightBounds, walked with their own importance() at the leaves. select() and probability() come
// in one overload per kind of primitive, each the same template (light_tree.cpp).
//
// Built once per commit by the scene (Scene::light_tree, MeshEmitters::finish). Flat arrays, no
// allocation per call.
#pragma once

#include "lights/light.h"
#include "lights/light_linking.h"
#include "lights/light_selection.h"

#include <cstdint>
#include <vector>

namespace toyrt {

struct EmissiveTriangle;  // lights/mesh_emitters.h

// A cluster, 64 bytes. The box bounds the angle it subtends (theta_u) and the receiver's horizon.
struct LightTreeNode {
  Vec3 lo{0.0f}, hi{0.0f};  // the box, every emitting point of the cluster
  Vec3 axis{0.0f, 0.0f, 1.0f};
  float power = 0.0f;              // the lights' summed LightBounds::power
  float cos_o = -1.0f, sin_o = 0;  // theta_o: every emitting normal within it of axis
  float cos_e = 0.0f;              // theta_e: each normal emits within it
  int32_t child = 0;               // internal: the first child (the second follows); leaf: -1 - first
  uint32_t count = 0;              // a leaf's lights: LightTree::order_[first, first + count)
  bool leaf() const { return child < 0; }
  uint32_t first() const { return uint32_t(-1 - child); }
};

class LightTree {
 public:
  // Trees deeper than this are never built (the median split takes over well before), so
  // probability() walks a path in a fixed array.
  static constexpr int kMaxDepth = 64;
  // Lights per leaf, at most: measured in docs/lights.md ("Light selection"), variance against
  // time per pick (1 is Conty Estevez and Kulla's, a bound at every level).
  static constexpr uint32_t kLeafSize = 8;

  LightTree() = default;
  explicit LightTree(const std::vector<Light>& lights, uint32_t leaf_size = kLeafSize);
  // Over any primitives by their bounds, in the order select() returns their indices.
  explicit LightTree(const std::vector<LightBounds>& bounds, uint32_t leaf_size = kLeafSize);

  // Light linking (lights/light_linking.h): per light, the receiver sets it lights. After this,
  // select() and probability() for a receiver in set `set` leave out the lights that do not light
  // that set, and never enter a cluster none of whose lights does (Cycles' light tree does the
  // same), so an unlinked lamp costs no sample. An empty vector (the default) links nothing.
  void set_receiver_sets(std::vector<uint64_t> per_light);
  bool linked() const { return !sets_.empty(); }

  // `lights` (or `triangles`) must be the ones the tree was built from; `set`: the receiver's
  // light-linking set, read only after set_receiver_sets.
  LightSelection select(const Light* lights, const Vec3& p, const Vec3& n, float u, uint8_t set = 0) const;
  float probability(const Light* lights, const Vec3& p, const Vec3& n, size_t index, uint8_t set = 0) const;
  LightSelection select(const EmissiveTriangle* triangles, const Vec3& p, const Vec3& n, float u) const;
  float probability(const EmissiveTriangle* triangles, const Vec3& p, const Vec3& n, size_t index) const;

  size_t light_count() const { return leaf_of_.size(); }
  size_t node_count() const { return nodes_.size(); }
  int depth() const { return depth_; }
  size_t memory_bytes() const;

 private:
  struct Weights {
    float first, second;
  };
  void build(const std::vector<LightBounds>& bounds, uint32_t leaf_size);
  // T: Light or EmissiveTriangle (instantiated in light_tree.cpp).
  // The receiver: its point, normal and light-linking set.
  struct At {
    Vec3 p, n;
    uint8_t set;
  };
  template <class T>
  LightSelection select_in(const T* items, const At& at, float u) const;
  template <class T>
  float probability_in(const T* items, const At& at, size_t index) const;
  template <class T>
  Weights top_weights(const T* items, const At& at) const;
  template <class T>
  Weights child_weights(const T* items, int32_t node, const At& at) const;
  template <class T>
  float weight(const T* items, size_t node, const At& at) const;
  // One primitive's importance, 0 for a light that does not light the receiver's set.
  template <class T>
  float item_weight(const T* items, uint32_t i, const At& at) const;
  template <class T>
  LightSelection pick_among(const T* items, const uint32_t* ids, size_t count, float total, float u, float scale,
                            const At& at) const;

  std::vector<LightTreeNode> nodes_;  // nodes_[0]: the root over the local lights, if any
  std::vector<int32_t> parent_;       // per node; -1 for the root
  std::vector<uint32_t> order_;       // the local lights, leaf by leaf
  std::vector<int32_t> leaf_of_;      // per light, its leaf; -1 for a light at infinity
  std::vector<uint32_t> distant_;     // the lights at infinity
  std::vector<uint64_t> sets_;        // light linking: per light, the receiver sets it lights; or empty
  std::vector<uint64_t> node_sets_;   // per node, the union of its lights' sets_ (empty with sets_)
  int depth_ = 0;
};

// The importance at p (normal n; 0: no receiver cosine) of every light a node bounds, as the tree
// weighs an inner node: zero only where none of them can reach p. Emissive triangles weigh
// themselves by it too (mesh_emitters.cpp), as a node of one whose `hull` (its three vertices:
// points whose convex hull holds every emitting point) bounds the angle it subtends from p more
// tightly and more cheaply than the box's eight corners.
float cluster_importance(const LightTreeNode& node, const Vec3& p, const Vec3& n, const Vec3* hull = nullptr,
                         int hull_count = 0);

}  // namespace toyrt
