#include "accel/morton_wide_builder.h"

#include "accel/morton_code.h"
#include "core/parallel.h"
#include "core/uninitialized_array.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <stdexcept>
#include <utility>
#include <vector>

namespace toyrt {

namespace {

// Fixed sizes, not derived from the thread count, so that the tree and its layout are the same on
// every machine.
// Larger subtrees are built as tasks of their own; on meshes under 128K primitives, subtrees
// larger than a 16th of the mesh (at least 512), so that a small mesh's top-down build is not one
// task on one core (at 10K triangles it was a sixth of the commit, serial).
constexpr uint32_t kTaskPrimitives = 8192;
uint32_t task_primitives(size_t count) {
  return uint32_t(std::clamp(count / 16, size_t(512), size_t(kTaskPrimitives)));
}
constexpr uint32_t kCodeBits = 30;  // 10 bits an axis, as the OpenCL build's default

// Bits 0-9 of v moved to bits 0, 3, ..., 27 in four shift-or-mask steps, each moving groups half
// as wide as the step before.
template <class U>
U spread10(U v) {
  v &= 0x3FFu;
  v = (v | v << 16) & 0x030000FFu;
  v = (v | v << 8) & 0x0300F00Fu;
  v = (v | v << 4) & 0x030C30C3u;
  v = (v | v << 2) & 0x09249249u;
  return v;
}

// The codes of eight primitives at once, lane by lane the same float operations as morton_cell
// (so the same codes): one primitive at a time the clamps were branches and the shifts and masks
// scalar, 11 % of a 1M-triangle commit's samples.
constexpr int kCodeLanes = 8;
using LaneFloats = float __attribute__((vector_size(kCodeLanes * sizeof(float))));
using LaneInts = uint32_t __attribute__((vector_size(kCodeLanes * sizeof(uint32_t))));
using LaneSigned = int32_t __attribute__((vector_size(kCodeLanes * sizeof(int32_t))));

[[gnu::always_inline]] inline LaneInts morton_codes(const BBox* boxes, const MortonFrame& f) {
  const float cells = float((1u << f.bits) - 1u);
  LaneInts code{};
  for (int a = 0; a < 3; ++a) {
    LaneFloats c;
    for (int k = 0; k < kCodeLanes; ++k) c[k] = 0.5f * boxes[k].lo[a] + 0.5f * boxes[k].hi[a];  // BBox::center
    const LaneFloats q = (c - f.lo[a]) * f.scale[a];
    const LaneFloats at_least_0 = q > 0.0f ? q : LaneFloats{};  // a NaN fails the comparison: 0
    const LaneFloats clamped = at_least_0 < cells ? at_least_0 : LaneFloats{} + cells;
    // In [0, 2^10 - 1]: the signed conversion truncates as the scalar unsigned one does.
    const LaneInts cell = LaneInts(__builtin_convertvector(clamped, LaneSigned));
    code |= spread10(cell) << (2 - a);
  }
  return code;
}

// Sort keys: the code above, the primitive's index below. Sorting by the code alone with a stable
// sort keeps equal codes in index order, as the reference's stable sort does.
using Key = uint64_t;
uint32_t code_of(Key k) { return uint32_t(k >> 32); }
uint32_t prim_of(Key k) { return uint32_t(k); }

// One stable pass over n keys by their 8-bit digit at `shift`, from `from` into `to`, over fixed
// chunks: each chunk counts its digits, one scan gives every (digit, chunk) its first slot, and each
// chunk scatters in order. Writes each digit's first slot to start[0..255] and n to start[256].
// Returns whether it scattered: always, unless skip_one_digit and the digit is the same for every
// key (the keys then stay in `from`).
bool scatter_by_digit(const Key* from, Key* to, size_t n, uint32_t shift, bool skip_one_digit, uint32_t start[257]) {
  const size_t chunks = chunk_count(n);
  std::vector<uint32_t> first(chunks * 256);
  for_each_chunk(n, [&](size_t c, size_t begin, size_t end) {
    uint32_t* count = &first[c * 256];
    std::fill(count, count + 256, 0u);
    for (size_t i = begin; i < end; ++i) ++count[(from[i] >> shift) & 255u];
  });
  uint32_t sum = 0;
  bool one_digit = false;
  for (uint32_t d = 0; d < 256; ++d) {
    start[d] = sum;
    for (size_t c = 0; c < chunks; ++c) sum += std::exchange(first[c * 256 + d], sum);
    one_digit |= sum - start[d] == n;
  }
  start[256] = sum;
  if (skip_one_digit && one_digit) return false;
  for_each_chunk(n, [&](size_t c, size_t begin, size_t end) {
    uint32_t next[256];
    std::copy(&first[c * 256], &first[c * 256] + 256, next);
    for (size_t i = begin; i < end; ++i) to[next[(from[i] >> shift) & 255u]++] = from[i];
  });
  return true;
}

// Stable least-significant-digit radix sort of n keys by the code's bits [low, high), 8 bits a
// pass; a pass whose digit is the same for every key is skipped. Returns the array holding the
// result (a or b).
Key* sort_by_bits(Key* a, Key* b, size_t n, uint32_t low, uint32_t high) {
  uint32_t start[257];
  for (uint32_t shift = 32 + low; shift < 32 + high; shift += 8)
    if (scatter_by_digit(a, b, n, shift, true, start)) std::swap(a, b);
  return a;
}

// The bits below the top digit of a bucket's n keys, sorted in cache on one thread, from `in`
// into `out` (both overwritten). Two passes of 11 bits where the bucket is large enough to fill
// their 2048 counters, three of 8 bits otherwise (a few thousand keys: the counters' upkeep would
// outweigh the pass saved); all passes' digits counted in one read. Three 8-bit passes reach bits
// 22-23, which belong to the top digit and are the same for every key of a bucket.
template <int kPasses>
void sort_bucket_by(Key* in, Key* out, size_t n) {
  constexpr uint32_t kDigitBits = kPasses == 2 ? 11 : 8, kDigits = 1u << kDigitBits;
  static_assert(kPasses * kDigitBits >= kCodeBits - 8, "the passes cover the bits below the top digit");
  uint32_t count[kPasses][kDigits] = {};
  auto digit = [](Key k, int p) { return uint32_t(k >> (32 + kDigitBits * p)) & (kDigits - 1); };
  for (size_t i = 0; i < n; ++i)
    for (int p = 0; p < kPasses; ++p) ++count[p][digit(in[i], p)];
  for (int p = 0; p < kPasses; ++p) {
    uint32_t sum = 0;
    for (uint32_t& c : count[p]) sum += std::exchange(c, sum);
  }
  Key* from = in;
  Key* to = out;
  for (int p = 0; p < kPasses; ++p) {
    for (size_t i = 0; i < n; ++i) to[count[p][digit(from[i], p)]++] = from[i];
    std::swap(from, to);
  }
  if (from != out) std::copy(from, from + n, out);  // an even number of passes ends in `in`
}

constexpr size_t kComparisonSortUpTo = 256;

void sort_bucket(Key* in, Key* out, size_t n) {
  // A small bucket (every bucket of a small mesh: at 10K triangles about 60 keys) by comparisons:
  // three passes' 768 counters to clear and sum cost more than its keys, and the radix sort was a
  // quarter of a 10K-triangle commit. The keys are distinct (the index is in the low half), so the
  // order is the same.
  if (n <= kComparisonSortUpTo) {
    std::copy(in, in + n, out);
    std::sort(out, out + n);
    return;
  }
  if (n >= 4096)
    sort_bucket_by<2>(in, out, n);
  else
    sort_bucket_by<3>(in, out, n);
}

// Sorts n keys by code (the keys are distinct, so the order is the one stable order whatever the
// thread count). An LSD sort by 8-bit digits moved every key through memory four times, the most
// costly stage of the build; here one pass scatters the keys by the code's top 8 bits into 256
// buckets (a few thousand keys each on a mesh), and each bucket sorts the rest in cache. A bucket
// too large for that (geometry crowded into one 256th of the frame) takes the parallel LSD sort.
// Returns the array holding the result (a or b).
Key* sort_by_code(Key* a, Key* b, size_t n) {
  constexpr uint32_t kTop = kCodeBits - 8;  // the top digit's lowest bit
  // 1 MB of keys (2 MB with the buffer sorted into): a few times a core's L2 cache, well inside
  // the last level; the largest bucket of the 1M sphere holds 31,343 keys.
  constexpr size_t kLargeBucket = size_t(1) << 17;
  uint32_t bucket[257];
  scatter_by_digit(a, b, n, 32 + kTop, false, bucket);  // every key in b, by its top digit
  tbb::parallel_for(tbb::blocked_range<uint32_t>(0, 256, 1), [&](const tbb::blocked_range<uint32_t>& r) {
    for (uint32_t d = r.begin(); d != r.end(); ++d) {
      const size_t at = bucket[d], size = bucket[d + 1] - at;
      if (size <= kLargeBucket) {
        sort_bucket(b + at, a + at, size);
      } else if (Key* sorted = sort_by_bits(b + at, a + at, size, 0, kTop); sorted != a + at) {
        std::copy(sorted, sorted + size, a + at);
      }
    }
  });
  return a;
}

struct Range {
  uint32_t begin, end;  // sorted slots [begin, end)
  uint32_t size() const { return end - begin; }
};

// A task's part of the tree: its wide nodes (its root at 0; interior children as indices into this
// array), and the root's slots whose subtrees are tasks of their own.
struct TaskTree {
  std::vector<WideNode> nodes;
  std::vector<std::pair<int, Range>> handed_on;  // (slot of node 0, range), in slot order
  std::vector<uint32_t> handed_to;               // the task each of them became
  BBox box;                                      // of the subtrees built here (not those handed on)
};

struct TopDown {
  const BBox* bounds;
  const Key* keys;
  uint32_t leaf_size;
  uint32_t task_size;  // task_primitives() of the mesh
  // False: the caller bounds the leaves (WideBuild::boxes_pending), and every box here is a
  // stand-in point that only marks its slot used.
  bool leaf_boxes;
  // Leaf boxes read here from boxes beyond a core's L2 cache (512 KB-1 MB on the machines
  // measured), where their random reads miss it: only when a caller asks for the boxes of a large
  // mesh (tests, benchmarks); below L2 the prefetches would be instructions for nothing.
  bool prefetch_leaf_boxes;

  // Where the range splits: the first slot whose code has the highest bit in which the range's
  // first and last codes differ (the codes are sorted, so every code in the range shares the bits
  // above it); equal codes split in the middle.
  uint32_t split(Range r) const {
    const uint32_t a = code_of(keys[r.begin]), z = code_of(keys[r.end - 1]);
    if (a == z) return r.begin + r.size() / 2;
    const uint32_t bit = 1u << (31 - __builtin_clz(a ^ z));
    uint32_t lo = r.begin, hi = r.end - 1;  // lo's code lacks the bit, hi's has it
    while (hi - lo > 1) {
      const uint32_t mid = lo + (hi - lo) / 2;
      (code_of(keys[mid]) & bit ? hi : lo) = mid;
    }
    return hi;
  }

  // The children of a wide node over r (more than leaf_size primitives): r split, then the most
  // populous child split while it holds more than leaf_size and the node has a free slot.
  int open(Range r, Range kids[kWidth]) const {
    int n = 1;
    kids[0] = r;
    while (n < kWidth) {
      int best = -1;
      uint32_t most = leaf_size;
      for (int i = 0; i < n; ++i)
        if (kids[i].size() > most) {
          best = i;
          most = kids[i].size();
        }
      if (best < 0) break;
      const uint32_t at = split(kids[best]);
      kids[n++] = {at, kids[best].end};
      kids[best].end = at;
    }
    return n;
  }

  BBox leaf_box(Range r) const {
    BBox b;
    for (uint32_t k = r.begin; k < r.end; ++k) b.extend(bounds[prim_of(keys[k])]);
    return b;
  }

  // Writes the wide node over r at out.nodes[at], its interior children side by side after the
  // array's end and their subtrees after them (depth first); returns the box of what it built.
  // Children of more than task_size (only ever met at a task's root) are handed on.
  BBox build(Range r, size_t at, TaskTree& out) const {
    Range kids[kWidth];
    const int n = open(r, kids);
    // The leaves' boxes are read at random (by sorted code, from boxes in mesh order): every leaf
    // child's reads are requested at once, before the first box is needed (the LBVH commit 2 %
    // faster at 200K-4M triangles when it still bounded its leaves here: docs/trace-speed.md,
    // thirty-third session; a mesh's commit now leaves them to Mesh::finish).
    if (prefetch_leaf_boxes)
      for (int i = 0; i < n; ++i)
        if (kids[i].size() <= leaf_size)
          for (uint32_t k = kids[i].begin; k < kids[i].end; ++k) __builtin_prefetch(&bounds[prim_of(keys[k])]);
    WideNode node;
    for (int a = 0; a < 3; ++a)
      for (int i = 0; i < kWidth; ++i) {
        node.bounds[a][i] = kInfinity;
        node.bounds[a + 3][i] = -kInfinity;
      }
    for (int i = 0; i < kWidth; ++i) node.child[i] = node.count[i] = 0;
    int inline_interior = 0;
    for (int i = 0; i < n; ++i) inline_interior += kids[i].size() > leaf_size && kids[i].size() <= task_size;
    size_t next = out.nodes.size();
    out.nodes.resize(next + size_t(inline_interior));
    BBox total;
    for (int i = 0; i < n; ++i) {
      BBox b;
      if (kids[i].size() <= leaf_size) {
        b = leaf_boxes ? leaf_box(kids[i]) : BBox{Vec3(0.0f), Vec3(0.0f)};
        node.child[i] = kids[i].begin;
        node.count[i] = kids[i].size();
      } else if (kids[i].size() > task_size) {
        out.handed_on.emplace_back(i, kids[i]);
        continue;  // its box is set when its task is done
      } else {
        node.child[i] = uint32_t(next);
        b = build(kids[i], next++, out);
      }
      node.set_box(i, b);
      total.extend(b);
    }
    out.nodes[at] = node;  // by index: the array may have grown while the children were built
    return total;
  }
};

}  // namespace

WideBuild build_morton_wide(const BBox* prim_bounds, size_t count, uint32_t leaf_size, bool leaf_boxes) {
  WideBuild built;
  if (count == 0) return built;
  // Slots and indices are 32-bit (an index rides in the low half of each sort key).
  if (count > size_t(UINT32_MAX)) throw std::length_error("host LBVH: more than 2^32 - 1 primitives");
  leaf_size = std::max(leaf_size, 1u);
  // The centres' bounds chunk by chunk, combined in chunk order.
  std::vector<BBox> chunk_centres(chunk_count(count));
  for_each_chunk(count, [&](size_t c, size_t begin, size_t end) {
    BBox box;  // a local: the array's element might alias prim_bounds, and shares lines with its neighbours
    for (size_t i = begin; i < end; ++i) box.extend(prim_bounds[i].center());
    chunk_centres[c] = box;
  });
  BBox centres;
  for (const BBox& b : chunk_centres) centres.extend(b);
  const MortonFrame frame = morton_frame(centres, MortonBits::k30);
  UninitializedArray<Key> a(count), b(count);
  // By fixed chunks (which primitives take the scalar tail does not depend on how TBB splits).
  for_each_chunk(count, [&](size_t, size_t begin, size_t end) {
    size_t i = begin;
    for (; i + kCodeLanes <= end; i += kCodeLanes) {
      const LaneInts codes = morton_codes(prim_bounds + i, frame);
      for (int k = 0; k < kCodeLanes; ++k) a.emplace(i + k, Key(uint32_t(codes[k])) << 32 | (i + k));
    }
    for (; i != end; ++i) {
      const Vec3 c = prim_bounds[i].center();
      const uint32_t code = spread10(morton_cell(c, frame, 0)) << 2 | spread10(morton_cell(c, frame, 1)) << 1 |
                            spread10(morton_cell(c, frame, 2));
      a.emplace(i, Key(code) << 32 | i);
    }
  });
  const Key* keys = sort_by_code(a.data(), b.data(), count);
  built.prim_ids.resize(count);
  for_each_chunk(count, [&](size_t, size_t begin, size_t end) {
    for (size_t i = begin; i != end; ++i) built.prim_ids[i] = prim_of(keys[i]);
  });
  if (count <= leaf_size) {
    built.wide.root_leaf_first = 0;
    built.wide.root_leaf_count = uint32_t(count);
    return built;
  }

  // Tasks level by level: each builds its subtree but for the children it hands on, which become
  // the next level's tasks in the order they were met, so task numbers (and the layout) do not
  // depend on which thread ran what.
  // The boxes' random reads cost only where they outgrow a core's L2 cache (512 KB-1 MB on the
  // machines measured): the leaves are left to the caller only there (at 10K triangles the
  // caller's bottom-up pass cost more than the reads: 0.352-0.358 -> 0.370-0.383 ms).
  const bool beyond_l2 = count * sizeof(BBox) > (size_t(1) << 20);
  leaf_boxes = leaf_boxes || !beyond_l2;
  const TopDown top_down{prim_bounds, keys, leaf_size, task_primitives(count), leaf_boxes, leaf_boxes && beyond_l2};
  built.boxes_pending = !leaf_boxes;
  std::vector<Range> ranges{{0u, uint32_t(count)}};
  std::vector<TaskTree> tasks;
  for (size_t level = 0; level < ranges.size();) {
    const size_t level_end = ranges.size();
    tasks.resize(level_end);
    tbb::parallel_for(tbb::blocked_range<size_t>(level, level_end, 1), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t t = r.begin(); t != r.end(); ++t) {
        // About one wide node for every 17 primitives on meshes (leaves of 8): reserved, so the
        // array rarely grows while the subtree is built. A larger task hands most of its subtree
        // on and builds only its top.
        tasks[t].nodes.reserve(std::min(ranges[t].size(), 8 * top_down.task_size) / 12 + 8);
        tasks[t].nodes.resize(1);
        tasks[t].box = top_down.build(ranges[t], 0, tasks[t]);
      }
    });
    for (size_t t = level; t < level_end; ++t)
      for (const auto& [slot, range] : tasks[t].handed_on) {
        tasks[t].handed_to.push_back(uint32_t(ranges.size()));
        ranges.push_back(range);
      }
    level = level_end;
  }
  // Boxes of the tasks' roots, from the last task up (a task is numbered after the one that
  // handed it on), and each task's place in the final array.
  std::vector<size_t> offset(tasks.size() + 1, 0);
  for (size_t t = tasks.size(); t-- > 0;) {
    TaskTree& task = tasks[t];
    for (size_t j = 0; j < task.handed_on.size(); ++j) {
      const BBox& b = tasks[task.handed_to[j]].box;
      const int slot = task.handed_on[j].first;
      task.nodes[0].set_box(slot, b);
      task.box.extend(b);
    }
  }
  for (size_t t = 0; t < tasks.size(); ++t) offset[t + 1] = offset[t] + tasks[t].nodes.size();
  built.wide.nodes.resize(offset.back());  // not zeroed (HugePageAllocator): every node is written below
  tbb::parallel_for(tbb::blocked_range<size_t>(0, tasks.size(), 1), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t t = r.begin(); t != r.end(); ++t) {
      const TaskTree& task = tasks[t];
      for (size_t i = 0; i < task.nodes.size(); ++i) {
        WideNode node = task.nodes[i];
        for (int k = 0; k < kWidth; ++k)
          if (node.count[k] == 0 && node.used(k)) node.child[k] += uint32_t(offset[t]);
        if (i == 0)
          for (size_t j = 0; j < task.handed_on.size(); ++j)
            node.child[task.handed_on[j].first] = uint32_t(offset[task.handed_to[j]]);
        if (leaf_boxes) sort_slots(node);  // else complete_wide_boxes() sorts them with their boxes
        built.wide.nodes[offset[t] + i] = node;
      }
    }
  });
  return built;
}

}  // namespace toyrt
