// PyScene::bvh_stats (py_scene.h): the numbers of a mesh's traced tree (wide nodes) or of the
// top level over instances (a binary Bvh), for inspection and benchmarks.
#include "python/py_scene.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace toyrt::binding {

py::dict PyScene::bvh_stats(int64_t mesh) {
  struct Numbers {
    size_t nodes = 0, leaves = 0, triangles = 0;
    int depth = 0;
    double sah_cost = 0.0, children_per_node = 0.0;
  };
  const Numbers n = read([&] {
    scene_.check_committed();
    Numbers r;
    if (mesh < 0) {  // the top level over instances: a binary Bvh
      const Bvh& bvh = scene_.top_level();
      r = {bvh.nodes.size(), bvh.leaf_count(), 0, bvh.depth(), bvh.sah_cost(), bvh.nodes.size() > 1 ? 2.0 : 0.0};
      return r;
    }
    if (size_t(mesh) >= scene_.mesh_count()) throw std::invalid_argument("unknown mesh id " + std::to_string(mesh));
    // A mesh's wide tree as traced: leaves are used slots with triangles (or the root leaf of a
    // tree without wide nodes), depth counts levels of wide nodes (0 for a single leaf).
    const WideBvh& wide = scene_.mesh(uint32_t(mesh)).wide_bvh();
    const WideStats st = wide_stats(wide, kBlockWidth);
    r.nodes = st.nodes;
    r.sah_cost = st.sah_cost;
    r.children_per_node = st.children_per_node;
    r.leaves = wide.root_leaf_count ? 1 : 0;
    r.triangles = wide.root_leaf_count;
    std::vector<std::pair<uint32_t, int>> stack;  // (wide node, its level: the root's is 1)
    if (!wide.nodes.empty()) stack.push_back({0, 1});
    while (!stack.empty()) {
      const auto [i, level] = stack.back();
      stack.pop_back();
      r.depth = std::max(r.depth, level);
      const WideNode& node = wide.nodes[i];
      for (int k = 0; k < kWidth; ++k) {
        if (!node.used(k)) continue;
        if (node.count[k] == 0) {
          stack.push_back({node.child[k], level + 1});
        } else {
          ++r.leaves;
          r.triangles += node.count[k];
        }
      }
    }
    return r;
  });
  py::dict d;
  d["nodes"] = n.nodes;
  d["leaves"] = n.leaves;
  d["depth"] = n.depth;
  d["sah_cost"] = n.sah_cost;
  d["children_per_node"] = n.children_per_node;
  if (mesh >= 0) d["triangles"] = n.triangles;
  return d;
}

}  // namespace toyrt::binding
