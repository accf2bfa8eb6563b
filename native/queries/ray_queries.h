// Every crossing along each ray of a batch (Open3D's count_intersections / list_intersections),
// decided by the exact test of queries/exact_crossing.h: each crossing of a closed mesh is
// counted once, also through shared edges and vertices.
#pragma once

#include "scene/scene.h"

#include <cstdint>
#include <vector>

namespace toyrt::queries {

// All crossings of a batch in CSR form: the crossings of ray i are entries
// [offsets[i], offsets[i + 1]), sorted by t (ties by instance, then prim). offsets has count + 1
// entries.
struct HitList {
  std::vector<int64_t> offsets;
  std::vector<uint32_t> ray;
  std::vector<float> t, u, v;
  std::vector<int32_t> mesh, instance, prim;
  size_t size() const { return t.size(); }
};

// What the two queries guarantee, for one ray in one mesh under one transform:
// - a crossing is a point where the ray, moved by an infinitesimal (e, e^2, e^3) in the mesh's
//   object space, passes through a triangle's interior; tnear <= t < tfar on its exact t for
//   the comparison with 0 and its double-rounded t otherwise;
// - rays with a zero or non-finite direction, a non-finite origin or tnear > tfar have none.
// Throws std::logic_error before commit, std::invalid_argument for bad thread counts.
void count_intersections(const Scene& scene, const RayBatch& rays, uint32_t* counts, int threads = 0);

// The crossings themselves. Throws std::length_error (naming the total) when they would be more
// than max_hits: the answer is counted first, so nothing is allocated past the bound.
HitList list_intersections(const Scene& scene, const RayBatch& rays, size_t max_hits, int threads = 0);

}  // namespace toyrt::queries
