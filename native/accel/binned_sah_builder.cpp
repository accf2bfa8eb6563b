// Binned SAH builder. Each range is binned along all three axes by centroid, the best of the
// bins - 1 planes per axis is taken if it beats making a leaf, and the two halves are built in
// parallel once they are large. Large ranges are also binned in parallel (a TBB reduction).
#include "accel/binned_sah_builder.h"

#include "core/parallel.h"
#include "core/uninitialized_array.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstring>
#include <memory>
#include <vector>

namespace toyrt {
namespace {

constexpr int kMaxBins = 64;
// Below this depth binning decides splits; past it, median splits halve the range, so the depth
// stays under kMaxBvhDepth even for adversarial inputs (2^32 primitives need 32 more levels).
constexpr int kMedianSplitDepth = kMaxBvhDepth - 34;

// A function no interprocedural pass looks into (see Builder::bin_range). Clang, which builds the
// fuzzer, has no noipa; it made no such clone.
#if defined(__clang__)
#define TOYRT_NO_IPA [[gnu::noinline]]
#else
#define TOYRT_NO_IPA [[gnu::noipa]]
#endif

struct RangeBounds {
  BBox box;      // of the primitives
  BBox centers;  // of their centroids
  void extend(const RangeBounds& o) {
    box.extend(o.box);
    centers.extend(o.centers);
  }
};

// Four floats in one SIMD register (GCC vector extensions: SSE on x86, NEON on ARM); the fourth
// lane is unused.
using float4 = float __attribute__((vector_size(16)));
using int4 = int32_t __attribute__((vector_size(16)));

// A bin's bounds in two registers: a primitive extends a bin with two instructions instead of
// six scalar minima and maxima, in the loop that is half of a whole commit.
struct BinBox {
  float4 lo = float4{} + kInfinity, hi = float4{} - kInfinity;
  // As BBox::extend (glm::min is b < a ? b : a), lane by lane.
  void extend(float4 plo, float4 phi) {
    lo = plo < lo ? plo : lo;
    hi = hi < phi ? phi : hi;
  }
  void extend(const BinBox& o) { extend(o.lo, o.hi); }
  BBox bbox() const { return {{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}}; }
};

// A primitive as the builder moves it: its box, with its index in the fourth lane of `lo`, in
// 32 bytes. The builder reorders these rather than indices into the caller's arrays, so binning,
// partitioning and bounding a range read it in order: with indices, every pass over a range read
// two arrays at random, and at a million triangles those reads were most of the build.
struct PrimRef {
  float4 lo;  // lane 3: the index (bits), read by id() only
  float4 hi;
  static PrimRef of(const BBox& b, uint32_t id) {
    float id_bits;
    std::memcpy(&id_bits, &id, sizeof id);
    return {float4{b.lo.x, b.lo.y, b.lo.z, id_bits}, float4{b.hi.x, b.hi.y, b.hi.z, 0.0f}};
  }
  uint32_t id() const {
    uint32_t bits;
    std::memcpy(&bits, reinterpret_cast<const char*>(&lo) + 3 * sizeof(float), sizeof bits);
    return bits;
  }
  // The centroid as BBox::center computes it: 0.5 lo + 0.5 hi is exact (halving is) up to its one
  // rounding, so it also equals the fused multiply-add the compiler may make of it. The index is
  // masked out first: as a float it is a denormal for any index below 2^23, and arithmetic on a
  // denormal takes a microcode assist (it doubled the binning's time). Lane 3 is 0.
  float4 center() const {
    const int4 xyz{-1, -1, -1, 0};
    return 0.5f * reinterpret_cast<float4>(reinterpret_cast<int4>(lo) & xyz) + 0.5f * hi;
  }
};
static_assert(sizeof(PrimRef) == 32, "two primitives a cache line");

struct Bins {
  std::array<BinBox, 3 * kMaxBins> box;
  std::array<uint32_t, 3 * kMaxBins> count{};
  void merge(const Bins& o, int bins) {
    for (int i = 0; i < 3 * bins; ++i) {
      box[i].extend(o.box[i]);
      count[i] += o.count[i];
    }
  }
};

class Builder {
 public:
  Builder(const BBox* bounds, size_t count, const BinnedSahConfig& cfg)
      : cfg_(cfg),
        count_(count),
        refs_(count),
        nodes_(new Node[2 * count - 1]),
        ranges_(2 * count - 1),
        subtree_nodes_(2 * count - 1) {
    cfg_.bins = std::clamp(cfg_.bins, 2, kMaxBins);
    cfg_.max_leaf = std::max(cfg_.max_leaf, 1u);
    several_threads_ = several_threads();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 16384), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i) refs_.emplace(i, PrimRef::of(bounds[i], uint32_t(i)));
    });
  }

  Bvh run() {
    const RangeBounds root = range_bounds(0, count_);
    next_node_ = 1;
    build(0, 0, count_, root, 1);
    return flatten();
  }

 private:
  RangeBounds range_bounds(size_t begin, size_t end) const {
    const PrimRef* refs = refs_.data();
    auto accumulate = [&](const tbb::blocked_range<size_t>& r, RangeBounds acc) {
      BinBox box, centers;
      for (size_t i = r.begin(); i != r.end(); ++i) {
        box.extend(refs[i].lo, refs[i].hi);
        const float4 c = refs[i].center();
        centers.extend(c, c);
      }
      acc.box.extend(box.bbox());
      acc.centers.extend(centers.bbox());
      return acc;
    };
    if (end - begin < cfg_.parallel_threshold) return accumulate({begin, end}, RangeBounds{});
    return tbb::parallel_reduce(tbb::blocked_range<size_t>(begin, end, 4096), RangeBounds{}, accumulate,
                                [](RangeBounds a, const RangeBounds& b) {
                                  a.extend(b);
                                  return a;
                                });
  }

  // Bins for a range of n primitives: the configured count for large ranges, fewer for small
  // ones, where sweeping 3 x bins planes would cost more than the primitives they sort (a
  // range of 16 has at most 15 distinct planes per axis anyway).
  int bins_for(size_t n) const { return int(std::clamp<size_t>(n / 2, 4, size_t(cfg_.bins))); }

  int bin_of(const float4& c, int axis, const BBox& centers, const Vec3& scale, int bins) const {
    // Clamped before the cast: centroids spanning more than FLT_MAX give inf * 0 = NaN here, and
    // a denormal extent an infinite scale; converting either to int is undefined (found by the
    // fuzzer, tests/fuzz). Such ranges all land in bin 0 and are split at the median.
    const float k = (c[axis] - centers.lo[axis]) * scale[axis];
    return k >= 1.0f ? int(std::min(k, float(bins - 1))) : 0;
  }

  Vec3 bin_scale(const BBox& centers, int bins) const {
    const Vec3 e = centers.extent();
    // (1 - eps) keeps the largest centroid in the last bin rather than one past it.
    const float s = float(bins) * (1.0f - 1e-6f);
    return {e.x > 0 ? s / e.x : 0.0f, e.y > 0 ? s / e.y : 0.0f, e.z > 0 ? s / e.z : 0.0f};
  }

  // Bins the range into `out`. Small ranges bin serially into `out` as it is, clearing only the
  // bins they use (a whole Bins is 4.6 KB, and clearing it per node cost more than binning the
  // small ranges near the leaves); large ones reduce fresh Bins in parallel.
  // Opaque to interprocedural passes: its only caller passes build()'s thread_local scratch, and
  // GCC made a clone (bin_range...constprop.isra) that named the thread_local itself; in the Python
  // module (-fPIC: a dynamic TLS model) its serial loop then called __tls_get_addr for every
  // primitive, spilling the loop's vectors around the call. Kept opaque, `out` is a plain
  // reference: the module's whole SAH commit at 1M triangles 8 % faster on 1 thread, 7 % on 2.
  TOYRT_NO_IPA void bin_range(size_t begin, size_t end, const BBox& centers, const Vec3& scale, int bins_used,
                              Bins& out) const {
    // bin_of on all three axes at once: the same operations lane by lane, so every primitive
    // lands in the bin the partition below (scalar bin_of) sends it by.
    const float4 origin{centers.lo.x, centers.lo.y, centers.lo.z, 0.0f}, factor{scale.x, scale.y, scale.z, 0.0f};
    const float4 last = float4{} + float(bins_used - 1), zero{};
    auto accumulate = [&](const tbb::blocked_range<size_t>& r, Bins& bins) {
      const PrimRef* refs = refs_.data();
      for (size_t i = r.begin(); i != r.end(); ++i) {
        const float4 lo = refs[i].lo, hi = refs[i].hi;
        const float4 k = (refs[i].center() - origin) * factor;
        // k >= 1 ? min(k, last) : 0, with NaN to 0 as bin_of: min keeps a NaN k, max drops it.
        float4 clamped = last < k ? last : k;
        clamped = clamped > zero ? clamped : zero;
        const int4 bin = __builtin_convertvector(clamped, int4);  // lane 3 (garbage) unused
        for (int a = 0; a < 3; ++a) {
          const int slot = a * kMaxBins + bin[a];
          bins.box[slot].extend(lo, hi);
          ++bins.count[slot];
        }
      }
    };
    if (end - begin < cfg_.parallel_threshold) {
      for (int a = 0; a < 3; ++a)
        for (int i = 0; i < bins_used; ++i) {
          out.box[a * kMaxBins + i] = BinBox{};
          out.count[a * kMaxBins + i] = 0;
        }
      accumulate({begin, end}, out);
      return;
    }
    out = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(begin, end, 4096), Bins{},
        [&](const tbb::blocked_range<size_t>& r, Bins bins) {
          accumulate(r, bins);
          return bins;
        },
        [&](Bins a, const Bins& b) {
          a.merge(b, kMaxBins);
          return a;
        });
  }

  struct Split {
    int axis = -1;
    int bin = 0;  // primitives in bins <= bin go left
    float cost = kInfinity;
  };

  Split find_split(const Bins& bins, const BBox& box, size_t n, int bins_used) const {
    Split best;
    const float inv_area = 1.0f / std::max(box.half_area(), 1e-30f);
    std::array<float, kMaxBins> right_cost;
    for (int a = 0; a < 3; ++a) {
      const int base = a * kMaxBins;
      BinBox acc;
      uint32_t cnt = 0;
      for (int i = bins_used - 1; i > 0; --i) {  // right side holds bins i .. bins-1
        acc.extend(bins.box[base + i]);
        cnt += bins.count[base + i];
        right_cost[i] = cnt ? acc.bbox().half_area() * float(cnt) : kInfinity;
      }
      acc = BinBox{};
      cnt = 0;
      for (int i = 0; i < bins_used - 1; ++i) {  // left side holds bins 0 .. i
        acc.extend(bins.box[base + i]);
        cnt += bins.count[base + i];
        if (cnt == 0 || cnt == n) continue;
        const float cost = cfg_.traversal_cost + cfg_.intersection_cost * inv_area *
                                                     (acc.bbox().half_area() * float(cnt) + right_cost[i + 1]);
        if (cost < best.cost) best = {a, i, cost};
      }
    }
    return best;
  }

  // Splits the range into the primitives left_of accepts (first, in their order) and the rest
  // (after them, in reverse order); returns where the second part starts. Without a branch on
  // the side: every primitive is written to both ends of a scratch array and only one end
  // advances. (std::partition branched on every one, and neighbours in a range fall on either
  // side about as often as not: a misprediction for most, at every level of the tree.)
  template <class LeftOf>
  size_t split_refs(size_t begin, size_t end, LeftOf left_of) {
    thread_local std::vector<PrimRef> scratch;  // ranges below parallel_threshold: 256 KB at most
    const size_t n = end - begin;
    if (scratch.size() < n) scratch.resize(n);
    PrimRef* out = scratch.data();
    PrimRef* refs = refs_.data();
    size_t lo = 0, hi = n - 1;
    for (size_t i = begin; i != end; ++i) {
      const PrimRef p = refs[i];
      const size_t left = left_of(p);
      out[lo] = p;
      out[hi] = p;
      lo += left;
      hi -= 1 - left;
    }
    std::copy(out, out + n, refs + begin);
    return begin + lo;
  }

  uint32_t make_leaf(uint32_t node, size_t begin, size_t end) {
    nodes_[node].first = uint32_t(begin);
    nodes_[node].count = uint32_t(end - begin);
    subtree_nodes_.emplace(node, 1u);
    return 1;
  }

  // Returns the number of nodes in the subtree.
  uint32_t build(uint32_t node, size_t begin, size_t end, const RangeBounds& rb, int depth) {
    // One relaxed load per node; the exception crosses parallel_invoke, which cancels the
    // sibling tasks and rethrows it on the calling thread.
    if (cfg_.cancel && cfg_.cancel->load(std::memory_order_relaxed)) throw BuildCancelled();
    nodes_[node].set_bbox(rb.box);
    const size_t n = end - begin;
    ranges_.emplace(node, SlotRange{uint32_t(begin), uint32_t(n)});
    if (n == 1 || n <= std::min(cfg_.leaf_without_search, cfg_.max_leaf)) return make_leaf(node, begin, end);

    size_t mid = begin;
    const Vec3 extent = rb.centers.extent();
    const bool coincident = extent.x <= 0 && extent.y <= 0 && extent.z <= 0;
    Split split;
    if (!coincident && depth < kMedianSplitDepth) {
      const int bins = bins_for(n);
      const Vec3 scale = bin_scale(rb.centers, bins);
      // One scratch Bins per thread: a node's binning and split search finish before its
      // children are built, and a task this thread runs while waiting inside the parallel
      // reduction finishes before the reduction's result is written here.
      thread_local Bins scratch;
      bin_range(begin, end, rb.centers, scale, bins, scratch);
      split = find_split(scratch, rb.box, n, bins);
      const float leaf_cost = cfg_.intersection_cost * float(n);
      if (n <= cfg_.max_leaf && leaf_cost <= split.cost) return make_leaf(node, begin, end);
      if (split.axis >= 0) {
        auto left_of = [&](const PrimRef& p) {
          return bin_of(p.center(), split.axis, rb.centers, scale, bins) <= split.bin;
        };
        // (Large ranges, near the root, are few: std::partition in place there, no scratch.)
        PrimRef* refs = refs_.data();
        mid = n < cfg_.parallel_threshold ? split_refs(begin, end, left_of)
                                          : size_t(std::partition(refs + begin, refs + end, left_of) - refs);
      }
    } else if (n <= cfg_.max_leaf) {
      return make_leaf(node, begin, end);
    }
    if (mid == begin || mid == end) {
      // No usable plane (coincident centroids, or too deep): split at the median of the widest
      // centroid axis, which always halves the range.
      mid = begin + n / 2;
      const int axis = max_dimension(extent);
      PrimRef* refs = refs_.data();
      std::nth_element(refs + begin, refs + mid, refs + end,
                       [&](const PrimRef& a, const PrimRef& b) { return a.center()[axis] < b.center()[axis]; });
    }

    const uint32_t left = next_node_.fetch_add(2);
    nodes_[node].first = left;
    nodes_[node].count = 0;
    uint32_t left_nodes = 0, right_nodes = 0;
    auto build_left = [&] { left_nodes = build(left, begin, mid, range_bounds(begin, mid), depth + 1); };
    auto build_right = [&] { right_nodes = build(left + 1, mid, end, range_bounds(mid, end), depth + 1); };
    if (n >= cfg_.task_threshold && several_threads_) {
      tbb::parallel_invoke(build_left, build_right);
    } else {
      build_left();
      build_right();
    }
    subtree_nodes_.emplace(node, 1 + left_nodes + right_nodes);
    return 1 + left_nodes + right_nodes;
  }

  // Re-lays the nodes in depth-first order, children pairs adjacent. Parallel builds allocate
  // node slots in whatever order tasks ran; this makes the layout, and so every traversal
  // result including ties, independent of the thread count, and keeps subtrees close in memory.
  Bvh flatten() const {
    Bvh bvh;
    bvh.prim_ids.resize(count_);
    const PrimRef* refs = refs_.data();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count_, 16384), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i) bvh.prim_ids[i] = refs[i].id();
    });
    bvh.nodes.resize(next_node_);  // not zeroed (HugePageAllocator): place() writes every one
    bvh.ranges.resize(next_node_);
    bvh.nodes[0] = nodes_[0];
    bvh.ranges[0] = ranges_[0];
    place(0, 0, 1, bvh);
    return bvh;
  }

  // Lays out the subtree below binary node `from` (already written at `to`): its children's pair
  // at `free`, then the left child's subtree, then the right's. The subtree sizes say where the
  // right one starts, so large subtrees are laid out in parallel, in the places a serial walk
  // would give them.
  void place(uint32_t from, uint32_t to, uint32_t free, Bvh& bvh) const {
    const Node& n = nodes_[from];
    if (n.is_leaf()) return;
    if (ranges_[from].count < cfg_.parallel_threshold) {
      std::vector<std::pair<uint32_t, uint32_t>> stack{{from, to}};  // (old index, new index)
      while (!stack.empty()) {
        const auto [old_index, new_index] = stack.back();
        stack.pop_back();
        const Node& m = nodes_[old_index];
        if (m.is_leaf()) continue;
        copy_children(m, new_index, free, bvh);
        stack.push_back({m.first + 1, free + 1});
        stack.push_back({m.first, free});
        free += 2;
      }
      return;
    }
    copy_children(n, to, free, bvh);
    const uint32_t right_free = free + 2 + (subtree_nodes_[n.first] - 1);
    tbb::parallel_invoke([&] { place(n.first, free, free + 2, bvh); },
                         [&] { place(n.first + 1, free + 1, right_free, bvh); });
  }

  void copy_children(const Node& n, uint32_t to, uint32_t at, Bvh& bvh) const {
    bvh.nodes[at] = nodes_[n.first];
    bvh.nodes[at + 1] = nodes_[n.first + 1];
    bvh.ranges[at] = ranges_[n.first];
    bvh.ranges[at + 1] = ranges_[n.first + 1];
    bvh.nodes[to].first = at;
  }

  BinnedSahConfig cfg_;
  bool several_threads_ = false;  // the arena the build runs on has more than one thread
  size_t count_;
  UninitializedArray<PrimRef> refs_;  // written in parallel by the constructor
  // Written before read, node by node, so not zeroed: 2n - 1 nodes is the bound (64 MB at a
  // million triangles), of which leaves of several primitives use a fraction, and zeroing all
  // of it made the kernel supply and clear every page.
  std::unique_ptr<Node[]> nodes_;
  // Every node's slots (first, count), as the builder knows them: collapse() reads them instead of
  // finding them by a serial walk of the tree (7-8 ms of the 2-thread commit at 1M triangles,
  // 40 ms at 4M).
  UninitializedArray<SlotRange> ranges_;
  UninitializedArray<uint32_t> subtree_nodes_;  // nodes in each node's subtree, for flatten()
  std::atomic<uint32_t> next_node_{0};
};

}  // namespace

Bvh build_binned_sah(const BBox* prim_bounds, size_t count, const BinnedSahConfig& config) {
  if (count == 0) return {};
  return Builder(prim_bounds, count, config).run();
}

}  // namespace toyrt
