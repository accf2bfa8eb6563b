#include "accel/lbvh_builder.h"

#include "accel/morton_code.h"

#include "lbvh_kernel_source.h"  // generated from kernels/lbvh.cl by CMake
#include "opencl/device.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <numeric>
#include <optional>

namespace toyrt {
namespace {

uint64_t spread_bits(uint64_t v, uint32_t bits) {
  uint64_t out = 0;
  for (uint32_t k = 0; k < bits; ++k) out |= ((v >> k) & 1u) << (3 * k);
  return out;
}

// The reference's codes spread the bits one at a time: the kernels and the host build spread them
// by shifts and masks, so equal codes check both.
uint64_t morton_code(const Vec3& c, const MortonFrame& f) {
  return (spread_bits(morton_cell(c, f, 0), f.bits) << 2) | (spread_bits(morton_cell(c, f, 1), f.bits) << 1) |
         spread_bits(morton_cell(c, f, 2), f.bits);
}

// As OpenCL's clz: defined for zero.
int clz32(uint32_t x) { return x ? __builtin_clz(x) : 32; }

// See common_prefix in kernels/lbvh.cl: equal keys are told apart by their indices.
int common_prefix(const std::vector<uint64_t>& keys, int64_t i, int64_t j) {
  const int64_t n = int64_t(keys.size());
  if (j < 0 || j >= n) return -1;
  const uint64_t a = keys[size_t(i)], b = keys[size_t(j)];
  if (a == b) return 64 + clz32(uint32_t(i ^ j));
  return __builtin_clzll(a ^ b);
}

void emit_node(const std::vector<uint64_t>& keys, int64_t i, LbvhNode& node) {
  const int d = common_prefix(keys, i, i + 1) - common_prefix(keys, i, i - 1) >= 0 ? 1 : -1;
  const int min_prefix = common_prefix(keys, i, i - d);
  int64_t max_len = 2;
  while (common_prefix(keys, i, i + max_len * d) > min_prefix) max_len *= 2;
  int64_t len = 0;
  for (int64_t t = max_len / 2; t >= 1; t /= 2)
    if (common_prefix(keys, i, i + (len + t) * d) > min_prefix) len += t;
  const int64_t j = i + len * d;
  const int node_prefix = common_prefix(keys, i, j);
  int64_t split = 0;
  for (int64_t div = 2;; div *= 2) {
    const int64_t t = (len + div - 1) / div;
    if (common_prefix(keys, i, i + (split + t) * d) > node_prefix) split += t;
    if (t == 1) break;
  }
  const int64_t gamma = i + split * d + std::min(d, 0);
  node.left = std::min(i, j) == gamma ? ~int32_t(gamma) : int32_t(gamma);
  node.right = std::max(i, j) == gamma + 1 ? ~int32_t(gamma + 1) : int32_t(gamma + 1);
}

BBox centroid_bounds_of(const BBox* prim_bounds, size_t count) {
  BBox b;
  for (size_t i = 0; i < count; ++i) b.extend(prim_bounds[i].center());
  return b;
}

}  // namespace

LbvhHierarchy build_lbvh_hierarchy_reference(const BBox* prim_bounds, size_t count, const LbvhConfig& config) {
  LbvhHierarchy h;
  if (count == 0) return h;
  const MortonFrame frame = morton_frame(centroid_bounds_of(prim_bounds, count), config.bits);
  std::vector<uint64_t> codes(count);
  for (size_t i = 0; i < count; ++i) codes[i] = morton_code(prim_bounds[i].center(), frame);
  h.values.resize(count);
  std::iota(h.values.begin(), h.values.end(), 0u);
  // Stable, as the kernels' radix sort: equal codes keep input order.
  std::stable_sort(h.values.begin(), h.values.end(), [&](uint32_t a, uint32_t b) { return codes[a] < codes[b]; });
  h.keys.resize(count);
  for (size_t k = 0; k < count; ++k) h.keys[k] = codes[h.values[k]];
  if (count == 1) return h;
  // Karras' top-down construction (node i has one end of its range at leaf i; root 0), then
  // renumbered as the kernel numbers nodes, by split position. The kernel builds the tree bottom
  // up another way (Apetrei's): equal trees are a check of both.
  std::vector<LbvhNode> karras(count - 1);
  for (size_t i = 0; i + 1 < count; ++i) emit_node(h.keys, int64_t(i), karras[i]);
  // Node i's split position: its left child's index (Karras numbers a left child by it).
  auto split_of = [&](int32_t i) {
    return karras[size_t(i)].left >= 0 ? karras[size_t(i)].left : ~karras[size_t(i)].left;
  };
  auto renumbered = [&](int32_t child) { return child >= 0 ? split_of(child) : child; };
  h.nodes.resize(count - 1);
  for (size_t i = 0; i + 1 < count; ++i) {
    LbvhNode& node = h.nodes[size_t(split_of(int32_t(i)))];
    node.left = renumbered(karras[i].left);
    node.right = renumbered(karras[i].right);
  }
  h.root = split_of(0);
  // Bounds bottom up: children have no fixed index order, so recurse from the root (post-order).
  std::vector<std::pair<int32_t, bool>> stack{{h.root, false}};
  auto bounds_of = [&](int32_t child, float* lo, float* hi) {
    if (child < 0) {
      const BBox& b = prim_bounds[h.values[size_t(~child)]];
      for (int a = 0; a < 3; ++a) lo[a] = b.lo[a], hi[a] = b.hi[a];
    } else {
      for (int a = 0; a < 3; ++a) lo[a] = h.nodes[size_t(child)].lo[a], hi[a] = h.nodes[size_t(child)].hi[a];
    }
  };
  while (!stack.empty()) {
    auto [i, children_done] = stack.back();
    stack.pop_back();
    LbvhNode& node = h.nodes[size_t(i)];
    if (!children_done) {
      stack.push_back({i, true});
      if (node.left >= 0) stack.push_back({node.left, false});
      if (node.right >= 0) stack.push_back({node.right, false});
      continue;
    }
    float llo[3], lhi[3], rlo[3], rhi[3];
    bounds_of(node.left, llo, lhi);
    bounds_of(node.right, rlo, rhi);
    for (int a = 0; a < 3; ++a) {
      node.lo[a] = std::fmin(llo[a], rlo[a]);
      node.hi[a] = std::fmax(lhi[a], rhi[a]);
    }
  }
  return h;
}

namespace {

// What run_opencl fills, whichever is non-null: `hierarchy` (the radix tree's nodes and root, and
// the keys when with_keys), `bvh` (the flat nodes written on the device), `wide` (the radix tree
// collapsed in place into wide nodes with leaves of up to leaf_size primitives).
struct LbvhOutputs {
  LbvhHierarchy* hierarchy = nullptr;
  bool with_keys = false;
  Bvh* bvh = nullptr;
  WideBuild* wide = nullptr;
  uint32_t leaf_size = 1;
};

// Runs the kernels and fills `out`.
void run_opencl(const BBox* prim_bounds, size_t count, const LbvhConfig& config, LbvhStats* stats,
                const LbvhOutputs& out) {
  LbvhHierarchy* hierarchy = out.hierarchy;
  Bvh* bvh = out.bvh;
  using namespace opencl;
  if (count >= size_t(INT32_MAX) / 2) throw OpenClError("LBVH: more than 2^30 primitives");
  const Device& dev = device();
  // 30-bit codes sort as 32-bit keys: half the bytes of 64-bit ones in every radix pass and in
  // the climb's prefix comparisons. One program per key width.
  const bool narrow = 3 * uint32_t(config.bits) <= 32;
  static std::atomic<bool> compiled[2] = {false, false};
  const bool compiling_now = !compiled[narrow].exchange(true);
  const Program& prog = narrow ? program("lbvh32", kLbvhKernelSource, "-cl-std=CL1.2 -DKEY=uint -DKEY_BITS=32")
                               : program("lbvh64", kLbvhKernelSource, "-cl-std=CL1.2 -DKEY=ulong -DKEY_BITS=64");
  const size_t key_size = narrow ? sizeof(uint32_t) : sizeof(uint64_t);
  double compile_ms = prog.compile_ms;
  if (compiling_now) {
    // Drivers finish compiling at a kernel's first launch (PoCL does): run every stage once on
    // three boxes so that this cost lands in compile_ms, not in the first build's time.
    const auto warm = std::chrono::steady_clock::now();
    const BBox tiny[3] = {{Vec3(0.0f), Vec3(1.0f)}, {Vec3(1.0f), Vec3(2.0f)}, {Vec3(2.0f), Vec3(3.0f)}};
    Bvh unused;
    LbvhOutputs warm_out;
    warm_out.bvh = &unused;  // write_bvh_nodes too: tests and benchmarks still build flat trees
    run_opencl(tiny, 3, config, nullptr, warm_out);
    compile_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - warm).count();
  }
  if (stats) {
    stats->device = dev.name;
    stats->compile_ms = compiling_now ? compile_ms : 0.0;
    stats->stages.clear();
  }
  const auto start = std::chrono::steady_clock::now();
  auto last = start;
  auto stage = [&](const char* name) {
    if (!stats) return;
    check(clFinish(dev.queue), "clFinish");
    const auto now = std::chrono::steady_clock::now();
    stats->stages.emplace_back(name, std::chrono::duration<double, std::milli>(now - last).count());
    last = now;
  };
  if (count == 0) return;
  const cl_uint n = cl_uint(count);

  // BBox is six packed floats (lo.xyz, hi.xyz): the layout the kernels read.
  static_assert(sizeof(BBox) == 6 * sizeof(float), "BBox must be six packed floats");
  Buffer bounds_buf(count * sizeof(BBox), CL_MEM_READ_ONLY, prim_bounds);
  // Centroid bounds: partial boxes on the device, the last few merged here.
  const size_t partials = std::min<size_t>(count, 1024);
  Buffer partial_buf(partials * 6 * sizeof(float));
  Kernel(prog.program, "centroid_bounds").arg(0, bounds_buf.get()).arg(1, n).arg(2, partial_buf.get()).run(partials);
  std::vector<float> partial(partials * 6);
  partial_buf.read(partial.data(), partial.size() * sizeof(float));
  BBox cb;
  for (size_t g = 0; g < partials; ++g) {
    cb.extend(Vec3(partial[6 * g], partial[6 * g + 1], partial[6 * g + 2]));
    cb.extend(Vec3(partial[6 * g + 3], partial[6 * g + 4], partial[6 * g + 5]));
  }
  const MortonFrame frame = morton_frame(cb, config.bits);
  stage("centroid bounds");

  Buffer keys[2] = {Buffer(count * key_size), Buffer(count * key_size)};
  Buffer values[2] = {Buffer(count * sizeof(uint32_t)), Buffer(count * sizeof(uint32_t))};
  Kernel(prog.program, "morton_codes")
      .arg(0, bounds_buf.get())
      .arg(1, n)
      .arg(2, frame.lo.x)
      .arg(3, frame.lo.y)
      .arg(4, frame.lo.z)
      .arg(5, frame.scale.x)
      .arg(6, frame.scale.y)
      .arg(7, frame.scale.z)
      .arg(8, cl_uint(frame.bits))
      .arg(9, keys[0].get())
      .arg(10, values[0].get())
      .run(count);
  stage("morton codes");

  // Radix sort, 8 bits a pass over the 3 x bits code bits.
  const cl_uint block = 4096;
  const size_t blocks = (count + block - 1) / block;
  Buffer hist(256 * blocks * sizeof(cl_uint));
  Kernel histogram(prog.program, "radix_histogram"), scan(prog.program, "radix_scan"),
      scatter(prog.program, "radix_scatter");
  const uint32_t key_bits = 3 * frame.bits;
  int in = 0;
  for (cl_uint shift = 0; shift < key_bits; shift += 8, in ^= 1) {
    histogram.arg(0, keys[in].get()).arg(1, n).arg(2, shift).arg(3, block).arg(4, hist.get()).run(blocks);
    scan.arg(0, hist.get()).arg(1, cl_uint(256 * blocks)).run(1);
    scatter.arg(0, keys[in].get())
        .arg(1, values[in].get())
        .arg(2, n)
        .arg(3, shift)
        .arg(4, block)
        .arg(5, hist.get())
        .arg(6, keys[in ^ 1].get())
        .arg(7, values[in ^ 1].get())
        .run(blocks);
  }
  stage("radix sort");

  std::vector<uint32_t> order(count);
  values[in].read(order.data(), count * sizeof(uint32_t));
  if (hierarchy && out.with_keys) {
    hierarchy->keys.resize(count);
    if (narrow) {
      std::vector<uint32_t> narrow_keys(count);
      keys[in].read(narrow_keys.data(), count * sizeof(uint32_t));
      std::copy(narrow_keys.begin(), narrow_keys.end(), hierarchy->keys.begin());
    } else {
      keys[in].read(hierarchy->keys.data(), count * sizeof(uint64_t));
    }
  }
  if (count == 1) {
    if (hierarchy) hierarchy->values = order;
    if (bvh) *bvh = to_bvh(LbvhHierarchy{{}, order, {}, 0}, prim_bounds);
    if (out.wide) {
      out.wide->wide = WideBvh{};
      out.wide->wide.root_leaf_count = 1;
      out.wide->prim_ids = order;
    }
    return;
  }
  const size_t internal = count - 1;
  Buffer nodes(internal * sizeof(LbvhNode)), ends(internal * sizeof(cl_int)), root_buf(sizeof(cl_int));
  // Each node's range of sorted leaves, for the flat nodes only: the collapse derives the ranges
  // from the split positions, so the wide build leaves the kernel's pointer null.
  std::optional<Buffer> internal_range;
  if (bvh) internal_range.emplace(internal * 2 * sizeof(cl_uint));
  ends.fill_zero(internal * sizeof(cl_int));
  Kernel(prog.program, "build_hierarchy")
      .arg(0, keys[in].get())
      .arg(1, n)
      .arg(2, bounds_buf.get())
      .arg(3, values[in].get())
      .arg(4, nodes.get())
      .arg(5, internal_range ? internal_range->get() : cl_mem(nullptr))
      .arg(6, ends.get())
      .arg(7, root_buf.get())
      .run(count);
  cl_int root = 0;
  root_buf.read(&root, sizeof root);
  stage("hierarchy and bounds");

  if (bvh) {
    bvh->nodes.resize(2 * count - 1);
    bvh->ranges.resize(2 * count - 1);
    static_assert(sizeof(bvh->ranges[0]) == 2 * sizeof(cl_uint), "a range is the kernel's uint2");
    const size_t bytes = bvh->nodes.size() * sizeof(Node), range_bytes = bvh->ranges.size() * sizeof(bvh->ranges[0]);
    Buffer flat(bytes, CL_MEM_WRITE_ONLY, bvh->nodes.data());  // written in place where the device can
    Buffer flat_range(range_bytes, CL_MEM_WRITE_ONLY, bvh->ranges.data());
    Kernel(prog.program, "write_bvh_nodes")
        .arg(0, nodes.get())
        .arg(1, bounds_buf.get())
        .arg(2, values[in].get())
        .arg(3, internal_range->get())
        .arg(4, n)
        .arg(5, root)
        .arg(6, flat.get())
        .arg(7, flat_range.get())
        .run(internal);
    flat.sync_to_host(bytes);
    flat_range.sync_to_host(range_bytes);
    bvh->prim_ids = order;
    stage("flat nodes");
  }
  if (out.wide) {
    // Read in place (a map: no copy on a CPU device). The flat nodes are not written at all: at
    // 1M triangles they were 80 MB of fresh pages and a third of the commit (docs/lbvh.md).
    LbvhTree tree;
    tree.nodes = static_cast<const LbvhNode*>(nodes.map_read(internal * sizeof(LbvhNode)));
    tree.prim_bounds = prim_bounds;
    tree.order = order.data();
    tree.leaves = count;
    tree.root = uint32_t(root);
    out.wide->wide = collapse(tree, out.leaf_size);
    nodes.unmap(tree.nodes);
    out.wide->prim_ids = hierarchy ? order : std::move(order);
    stage("collapse");
  }
  if (hierarchy) {
    hierarchy->values = std::move(order);
    hierarchy->nodes.resize(internal);
    nodes.read(hierarchy->nodes.data(), internal * sizeof(LbvhNode));
    hierarchy->root = root;
  }
  check(clFinish(dev.queue), "clFinish");
}

}  // namespace

LbvhHierarchy build_lbvh_hierarchy_opencl(const BBox* prim_bounds, size_t count, const LbvhConfig& config,
                                          LbvhStats* stats, bool with_keys) {
  LbvhHierarchy h;
  LbvhOutputs out;
  out.hierarchy = &h;
  out.with_keys = with_keys;
  run_opencl(prim_bounds, count, config, stats, out);
  return h;
}

Bvh to_bvh(const LbvhHierarchy& h, const BBox* prim_bounds) {
  Bvh bvh;
  const size_t count = h.values.size();
  if (count == 0) return bvh;
  bvh.prim_ids = h.values;
  bvh.nodes.resize(2 * count - 1);
  if (count == 1) {
    bvh.nodes[0].set_bbox(prim_bounds[h.values[0]]);
    bvh.nodes[0].first = 0;
    bvh.nodes[0].count = 1;
    return bvh;
  }
  // The same placement as the write_bvh_nodes kernel: node g's children at 1 + 2g and 2 + 2g.
  auto place = [&](int32_t child, size_t at) {
    Node& node = bvh.nodes[at];
    if (child >= 0) {
      const LbvhNode& src = h.nodes[size_t(child)];
      node.set_bbox({{src.lo[0], src.lo[1], src.lo[2]}, {src.hi[0], src.hi[1], src.hi[2]}});
      node.first = 1u + 2u * uint32_t(child);
      node.count = 0;
    } else {
      node.set_bbox(prim_bounds[h.values[size_t(~child)]]);
      node.first = uint32_t(~child);
      node.count = 1;
    }
  };
  place(h.root, 0);
  for (size_t g = 0; g + 1 < count; ++g) {
    place(h.nodes[g].left, 1 + 2 * g);
    place(h.nodes[g].right, 2 + 2 * g);
  }
  return bvh;
}

Bvh build_lbvh(const BBox* prim_bounds, size_t count, const LbvhConfig& config, LbvhStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  Bvh bvh;
  LbvhOutputs out;
  out.bvh = &bvh;
  run_opencl(prim_bounds, count, config, stats, out);
  if (stats)
    stats->build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return bvh;
}

WideBuild build_lbvh_wide(const BBox* prim_bounds, size_t count, uint32_t leaf_size, const LbvhConfig& config,
                          LbvhStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  WideBuild built;
  LbvhOutputs out;
  out.wide = &built;
  out.leaf_size = leaf_size;
  run_opencl(prim_bounds, count, config, stats, out);
  if (stats)
    stats->build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return built;
}

Bvh build_lbvh_reference(const BBox* prim_bounds, size_t count, const LbvhConfig& config) {
  return to_bvh(build_lbvh_hierarchy_reference(prim_bounds, count, config), prim_bounds);
}

}  // namespace toyrt
