#include "geometry/mesh.h"

#include "accel/wide_traverse.h"
#include "core/parallel.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#if defined(__SSE__)
#include <immintrin.h>
#endif

namespace toyrt {
namespace {

// Writes a finished block to the blocks array past the caches (non-temporal stores), for arrays
// too large to stay cached (40-48 MB at a million triangles): written once and not read again by
// the commit, whose ordinary stores first read every line they fill. The block is made in a local
// copy so that each of its lines is written whole in one go, which is what lets the write-combining
// buffers send full lines. The 1M and 4M LBVH commits 4 % faster (32-byte stores; 16-byte ones
// 1-3 %), the SAH commit unchanged (docs/trace-speed.md, thirty-third session).
void store_streaming(TriangleBlock& to, const TriangleBlock& from) {
#if defined(__AVX__)
  using Row = __m256;
  static_assert(sizeof(TriangleBlock) % sizeof(Row) == 0 && alignof(TriangleBlock) >= alignof(Row));
  for (size_t q = 0; q < sizeof(TriangleBlock) / sizeof(Row); ++q)
    _mm256_stream_ps(reinterpret_cast<float*>(&to) + q * 8, reinterpret_cast<const Row*>(&from)[q]);
#elif defined(__SSE__)
  using Row = __m128;
  static_assert(sizeof(TriangleBlock) % sizeof(Row) == 0 && alignof(TriangleBlock) >= alignof(Row));
  for (size_t q = 0; q < sizeof(TriangleBlock) / sizeof(Row); ++q)
    _mm_stream_ps(reinterpret_cast<float*>(&to) + q * 4, reinterpret_cast<const Row*>(&from)[q]);
#else
  to = from;
#endif
}

// Orders this thread's streamed stores before what follows (the end of a parallel task, after
// which other threads read the blocks): the release and acquire of C++ atomics are plain moves on
// x86, which do not order non-temporal stores.
void end_streaming() {
#if defined(__SSE__)
  _mm_sfence();
#endif
}

bool is_degenerate(const Vec3& p0, const Vec3& p1, const Vec3& p2) {
  if (p0 == p1 || p1 == p2 || p2 == p0) return true;
  const DVec3 n = glm::cross(DVec3(p1) - DVec3(p0), DVec3(p2) - DVec3(p0));
  return n.x == 0.0 && n.y == 0.0 && n.z == 0.0;
}

}  // namespace

Mesh::Mesh(std::vector<Vec3> vertices, std::vector<Triangle> triangles)
    : vertices_(std::move(vertices)), triangles_(std::move(triangles)) {
  if (triangles_.size() >= size_t(INT32_MAX)) throw std::invalid_argument("a mesh holds at most 2^31 - 1 triangles");
  // Both checks run without an early exit, so their loops compile to straight-line code, and
  // look for the culprit only when there is one: adding the 1M sphere 6.9 -> 5.0 ms, the 200K
  // soup 3.7 -> 2.9 ms (bench_trace times adding a mesh with its commit). On two cores the checks
  // saved 0.2-0.6 ms more at 1M: not worth running them outside a commit's thread limit. x - x is NaN
  // for an inf or a NaN and 0 otherwise, so `spread` stays 0 exactly when every coordinate is
  // finite.
  float spread = 0.0f;
  for (const Vec3& v : vertices_) {
    spread += (v.x - v.x) + (v.y - v.y) + (v.z - v.z);
    bounds_.extend(v);
  }
  if (spread != 0.0f)
    for (size_t i = 0; i < vertices_.size(); ++i)
      if (!is_finite(vertices_[i]))
        throw std::invalid_argument("vertex " + std::to_string(i) + " is not finite (NaN or inf)");
  const size_t n = vertices_.size();
  uint32_t highest = 0;
  for (const Triangle& t : triangles_) highest = std::max({highest, t.x, t.y, t.z});
  if (!triangles_.empty() && highest >= n)
    for (size_t i = 0; i < triangles_.size(); ++i) {
      const Triangle& t = triangles_[i];
      if (t.x >= n || t.y >= n || t.z >= n)
        throw std::invalid_argument("triangle " + std::to_string(i) + " indexes a vertex out of range (" +
                                    std::to_string(n) + " vertices)");
    }
}

Mesh::Prepared Mesh::prepare() {
  // One pass over fixed chunks, so that the builder's slots (and so the tree) are the same
  // whatever the thread count: each triangle's box is written at its own index, the triangles
  // that can be hit are marked and counted chunk by chunk, and their boxes bounded. Where every
  // triangle can be hit (most meshes) those boxes are the builder's input as they stand; else a
  // second pass packs the hittable ones from each chunk's offset. (Two passes over the mesh, one
  // to mark and one to write the boxes, read every triangle and vertex twice: 9 ms of the 1M
  // commit on a first-generation EPYC.) Nothing is constructed or zeroed beforehand on one
  // thread (UninitializedArray).
  const size_t n = triangles_.size();
  const size_t chunks = chunk_count(n);
  UninitializedArray<BBox> boxes(n);
  UninitializedArray<uint8_t> keep(n);
  std::vector<uint32_t> offset(chunks + 1, 0u);
  std::vector<BBox> chunk_bounds(chunks);
  for_each_chunk(n, [&](size_t c, size_t begin, size_t end) {
    uint32_t kept = 0;
    BBox hittable_bounds;
    for (size_t i = begin; i < end; ++i) {
      const Triangle& t = triangles_[i];
      const Vec3 &p0 = vertices_[t.x], &p1 = vertices_[t.y], &p2 = vertices_[t.z];
      BBox b;
      b.extend(p0);
      b.extend(p1);
      b.extend(p2);
      boxes.emplace(i, b);
      const bool hittable = !is_degenerate(p0, p1, p2);
      keep.emplace(i, uint8_t(hittable));
      kept += hittable;
      if (hittable) hittable_bounds.extend(b);
    }
    offset[c + 1] = kept;
    chunk_bounds[c] = hittable_bounds;
  });
  bounds_ = BBox{};
  for (size_t c = 0; c < chunks; ++c) {
    offset[c + 1] += offset[c];
    bounds_.extend(chunk_bounds[c]);
  }
  Prepared p;
  p.count = offset[chunks];
  if (p.count == n) {  // slot i is triangle i
    p.boxes = std::move(boxes);
    return p;
  }
  p.boxes = UninitializedArray<BBox>(p.count);
  p.valid = UninitializedArray<uint32_t>(p.count);
  for_each_chunk(n, [&](size_t c, size_t begin, size_t end) {
    size_t slot = offset[c];
    for (size_t i = begin; i < end; ++i) {
      if (!keep[i]) continue;
      p.boxes.emplace(slot, boxes[i]);
      p.valid.emplace(slot++, uint32_t(i));
    }
  });
  return p;
}

void Mesh::build(BuilderKind kind, const BuildConfig& config, BuildStats* stats) {
  Prepared prepared = prepare();
  BuildConfig mine = config;
  mine.sah.leaf_without_search = kBlockWidth;  // the collapse makes leaves of one block
  mine.leaf_boxes_by_caller = true;            // finish() reads every leaf's vertices anyway
  WideBuild built = build_wide_bvh(kind, prepared.boxes.data(), prepared.count, kBlockWidth, mine, stats);
  // The boxes are freed only after finish(): freeing them before it (24 MB less at the peak at 1M)
  // made the 4M commit on two threads 845 -> 1600 ms in bench_trace, its collapse and blocks
  // stalling up to 0.5 s on fresh pages (docs/trace-speed.md, twenty-second session).
  finish(std::move(built), prepared.valid);
}

void Mesh::finish(WideBuild built, const UninitializedArray<uint32_t>& valid) {
  wide_ = std::move(built.wide);
  // Builder slots; freed on return, as the blocks hold the triangle indices.
  const std::vector<uint32_t> prim_ids = std::move(built.prim_ids);
  const uint32_t* triangle_of = valid.size() ? valid.data() : nullptr;  // builder slot -> triangle, if not equal
  // Copy every leaf's triangles into blocks and point the wide leaves at them. Each node's first
  // block comes from a serial count in node order, so the blocks are laid out the same whatever
  // the thread count; the copying (a random read of three vertices per triangle) runs in parallel.
  auto blocks_of = [](uint32_t count) { return uint32_t((count + kBlockWidth - 1) / kBlockWidth); };
  std::vector<uint32_t> first_block(wide_.nodes.size());
  uint32_t block_count = blocks_of(wide_.root_leaf_count);
  for (size_t i = 0; i < wide_.nodes.size(); ++i) {
    first_block[i] = block_count;
    for (int k = 0; k < kWidth; ++k) block_count += blocks_of(wide_.nodes[i].count[k]);
  }
  prefetch_blocks_ = leaf_in_flight_ = false;  // until the blocks are made
  blocks_.clear();
  blocks_.shrink_to_fit();
  blocks_.resize(block_count);  // exactly, and not zeroed (HugePageAllocator): every field is written below
  // Blocks beyond the caches are streamed past them; blocks that fit are written there, for the
  // rays that follow the commit.
  const bool beyond_caches = blocks_.size() * sizeof(TriangleBlock) > kPrefetchBlockBytes;
  const bool bound_leaves = built.boxes_pending;
  // Copies a leaf's triangles into its blocks; returns their box where the builder left the
  // leaves' boxes to this copy (boxes_pending), else an empty one.
  auto emit = [&](uint32_t first, uint32_t count, uint32_t start) {
    BBox box;
    for (uint32_t k = 0; k < count; k += kBlockWidth) {
      TriangleBlock b;
      const int lanes = int(std::min<uint32_t>(kBlockWidth, count - k));
      // A leaf's triangles lie anywhere in the mesh's arrays: their vertex indices are all
      // requested before the first is read, so the block's misses overlap (in one process with
      // both forms alternating: the 200K soup's LBVH commit 0.95-0.96 of its time, 1M 0.985-0.997;
      // reading all indices into a local array first: the soup 0.94-0.97, but 1M 1.01).
      for (int lane = 0; lane < lanes; ++lane) {
        const uint32_t slot = prim_ids[first + k + lane];
        b.prim[lane] = triangle_of ? triangle_of[slot] : slot;
        __builtin_prefetch(&triangles_[b.prim[lane]]);
      }
      for (int lane = 0; lane < lanes; ++lane)
        for (int v = 0; v < 3; ++v) {
          const Vec3& p = vertices_[triangles_[b.prim[lane]][v]];
          if (bound_leaves) box.extend(p);
          for (int a = 0; a < 3; ++a) b.p[v][a][lane] = p[a];
        }
      for (int lane = lanes; lane < kBlockWidth; ++lane) {  // unused: no triangle, and no NaN garbage
        b.prim[lane] = kNoTriangle;
        for (int v = 0; v < 3; ++v)
          for (int a = 0; a < 3; ++a) b.p[v][a][lane] = 0.0f;
      }
      if (beyond_caches)
        store_streaming(blocks_[start + k / kBlockWidth], b);
      else
        blocks_[start + k / kBlockWidth] = b;
    }
    return box;
  };
  if (wide_.root_leaf_count) {
    emit(wide_.root_leaf_first, wide_.root_leaf_count, 0);
    if (beyond_caches) end_streaming();
    wide_.root_leaf_first = 0;
  }
  // Beyond a few megabytes of vertices and vertex indices, a node's leaves read lines that are in
  // no cache, and when the mesh's vertices are in no spatial order (a triangle soup) each
  // triangle's are a miss of their own: every leaf triangle's vertex indices of a node are
  // requested, then its vertices, before the first block is made, so that their misses overlap.
  // In one process with both forms alternating, the LBVH commit: the 200K soup 0.75-0.78 of its
  // time, 1M 0.94-0.96, 4M 0.91, 320K 0.97-0.98 (SAH: soup 0.93-0.95, 1M 0.97-0.98); but 180K
  // 1.03-1.05 and 100K 1.08 (vertices in ring order, whose lines the hardware prefetcher already
  // brings: the two extra passes were pure cost), hence kScatteredReadBytes. Forced inline: as a
  // call, GCC judged this loads-and-prefetches-only lambda pure and dropped it.
  const bool scattered_reads =
      vertices_.size() * sizeof(Vec3) + triangles_.size() * sizeof(Triangle) > kScatteredReadBytes;
  auto request_leaf_vertices = [&](const WideNode& n) __attribute__((always_inline)) {
    for (int k = 0; k < kWidth; ++k)
      for (uint32_t j = 0; j < n.count[k]; ++j) {
        const uint32_t slot = prim_ids[n.child[k] + j];
        __builtin_prefetch(&triangles_[triangle_of ? triangle_of[slot] : slot]);
      }
    for (int k = 0; k < kWidth; ++k)
      for (uint32_t j = 0; j < n.count[k]; ++j) {
        const uint32_t slot = prim_ids[n.child[k] + j];
        const Triangle& tri = triangles_[triangle_of ? triangle_of[slot] : slot];
        __builtin_prefetch(&vertices_[tri[0]]);
        __builtin_prefetch(&vertices_[tri[1]]);
        __builtin_prefetch(&vertices_[tri[2]]);
      }
  };
  // Copies node i's leaves into their blocks and points its leaf slots at them.
  auto emit_node = [&](size_t i) {
    WideNode& n = wide_.nodes[i];
    uint32_t start = first_block[i];
    if (scattered_reads) request_leaf_vertices(n);
    for (int k = 0; k < kWidth; ++k) {
      if (!n.count[k]) continue;
      const BBox box = emit(n.child[k], n.count[k], start);
      if (bound_leaves) n.set_box(k, box);
      n.child[k] = start;
      start += blocks_of(n.count[k]);
    }
  };
  if (!bound_leaves) {
    // Grains of 64 nodes (about 2,500 triangles): with 512 a 10K-triangle mesh's ~280 nodes were
    // one task, and this copy ran on one thread (0.28 -> 0.18 ms of the 10K commit on two threads).
    tbb::parallel_for(tbb::blocked_range<size_t>(0, wide_.nodes.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i) emit_node(i);
      if (beyond_caches) end_streaming();
    });
  } else {
    // The builder left the boxes to this copy: each subtree is finished before its parent, which
    // then bounds its interior slots from the children just written (still in cache). A serial
    // sweep over the nodes after the copy took 4.5 ms at 1M, more than it saved the builder. The
    // blocks' places were fixed above, so the layout does not depend on the thread count.
    complete_wide_boxes(
        wide_, [&](uint32_t i) { emit_node(i); },
        [&] {
          if (beyond_caches) end_streaming();
        });
    if (beyond_caches) end_streaming();
  }
  // Blocks beyond the caches are fetched ahead by the closest-hit walk; where they fit, the
  // prefetches were pure cost (1-3 % slower at 10K and 100K triangles, 3-8 % faster at 1M).
  prefetch_blocks_ = beyond_caches;
  leaf_in_flight_ = blocks_.size() * sizeof(TriangleBlock) > kLeafInFlightBlockBytes;
  built_ = true;
}

template <bool AnyHit, bool kSkip, bool kOverlapLeaves>
bool Mesh::trace(const Vec3& org, const Vec3& dir, float tnear, float& tfar, float& u, float& v, int32_t& prim,
                 bool ray_checked, int32_t skip) const {
  // A valid world ray can overflow in an instance's object space (a huge inverse scale): with a
  // NaN in every inverse direction component, each slab test keeps its NaN-free bounds, so even
  // the empty slots of a wide node "hit" and send the walk back to the root until its stack
  // overflows (found by tests/fuzz). Such a ray cannot hit anything here.
  if (!ray_checked && (!is_finite(org) || !is_finite(dir) || dir == Vec3(0.0f))) return false;
  const float segment_end = tfar;
  const RayBoxData box_ray = make_ray_box_data(org, dir);
  const WatertightRay tri_ray = make_watertight_ray(org, dir);
  const BlockRay block_ray = make_block_ray(tri_ray);
  const TriangleBlock* blocks = blocks_.data();
  uint32_t found_block = 0;
  int found_lane = 0;
  bool recorded = false;
  // kOverlapLeaves: see Mesh::intersect.
  const bool found = traverse_wide<AnyHit, kOverlapLeaves>(
      wide_, box_ray, tnear, tfar,
      [&](uint32_t first, uint32_t count, float& t_max) __attribute__((always_inline)) {
        bool hit = false;
        const uint32_t end = first + (count + kBlockWidth - 1) / kBlockWidth;
        for (uint32_t k = first; k < end; ++k) {
          hit |= intersect_block<AnyHit, kSkip>(
              tri_ray, block_ray, blocks[k], tnear, t_max, skip, [&](int lane, float t) __attribute__((always_inline)) {
                // The nearest so far; and the first this walk finds even where its float distance
                // only ties t_max (the block test put it before t_max in the scaled domain; t_max
                // stays, and the end below keeps t < tfar). Without that, a mesh reported such a
                // lane as hit without naming it, and the walk's answer was block 0's first
                // triangle (found by tests/fuzz: two coincident instances, the second one's
                // crossing tying the first's).
                if (t < t_max || !recorded) {
                  t_max = std::min(t, t_max);
                  found_block = k;
                  found_lane = lane;
                  recorded = true;
                }
              });
          if (AnyHit && hit) return true;
        }
        return hit;
      },
      [ blocks, prefetch = prefetch_blocks_ ](uint32_t first, uint32_t) __attribute__((always_inline)) {
        // The leaf's first block, its five cache lines (most leaves are one block).
        if (!prefetch) return;
        const char* b = reinterpret_cast<const char*>(blocks + first);
        for (size_t line = 0; line < sizeof(TriangleBlock); line += 64) __builtin_prefetch(b + line);
      });
  if constexpr (!AnyHit) {
    if (found) {
      const TriangleBlock& b = blocks[found_block];
      refine_hit(org, dir, b.vertex(found_lane, 0), b.vertex(found_lane, 1), b.vertex(found_lane, 2), tnear, tfar, u,
                 v);
      // The float test put the hit before the segment's end, but its double-precision distance
      // can round onto it (t = tfar = 0 in the fuzzer's case): keep the promise t < tfar. A hit
      // implies tnear < segment_end, so the result stays >= tnear.
      if (!(tfar < segment_end)) tfar = std::nextafter(segment_end, -kInfinity);
      prim = int32_t(b.prim[found_lane]);
    }
  }
  return found;
}

bool Mesh::intersect(const Vec3& org, const Vec3& dir, float tnear, float& tfar, float& u, float& v, int32_t& prim,
                     bool ray_checked, int32_t skip) const {
  // Two walks, one for rays that name the triangle they leave and one for those that do not:
  // with one, camera rays paid 1-2 % for the test they never need. And each twice: where the
  // blocks are beyond the caches, the walk visits a stacked node while the nearest leaf's block
  // arrives (closest_hit_wide's kOverlapLeaves); meshes in cache keep the plain walk, which lost
  // 1-3 % of its speed at 10K triangles when both were compiled into one function.
  if (prefetch_blocks_)
    return skip == kInvalidId ? trace<false, false, true>(org, dir, tnear, tfar, u, v, prim, ray_checked, skip)
                              : trace<false, true, true>(org, dir, tnear, tfar, u, v, prim, ray_checked, skip);
  return skip == kInvalidId ? trace<false, false, false>(org, dir, tnear, tfar, u, v, prim, ray_checked, skip)
                            : trace<false, true, false>(org, dir, tnear, tfar, u, v, prim, ray_checked, skip);
}

bool Mesh::occluded(const Vec3& org, const Vec3& dir, float tnear, float tfar, bool ray_checked, int32_t skip) const {
  float u, v;
  int32_t prim;
  // Where the blocks are far beyond the caches, the any-hit walk keeps a leaf in flight
  // (any_hit_wide's kOverlapLeaves).
  if (leaf_in_flight_)
    return skip == kInvalidId ? trace<true, false, true>(org, dir, tnear, tfar, u, v, prim, ray_checked, skip)
                              : trace<true, true, true>(org, dir, tnear, tfar, u, v, prim, ray_checked, skip);
  return skip == kInvalidId ? trace<true, false, false>(org, dir, tnear, tfar, u, v, prim, ray_checked, skip)
                            : trace<true, true, false>(org, dir, tnear, tfar, u, v, prim, ray_checked, skip);
}

size_t Mesh::memory_bytes() const {
  return vertices_.capacity() * sizeof(Vec3) + triangles_.capacity() * sizeof(Triangle) +
         blocks_.capacity() * sizeof(TriangleBlock) + wide_.nodes.capacity() * sizeof(WideNode);
}

}  // namespace toyrt
