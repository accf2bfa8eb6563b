// compute_closest_points and compute_distance (queries/point_queries.h): branch and bound over
// the top-level BVH, then each reached instance's wide BVH and triangle blocks, in world space and
// double precision.
#include "core/parallel.h"
#include "queries/closest_point_triangle.h"
#include "queries/point_queries.h"
#include "queries/point_walk.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>

namespace toyrt::queries {
namespace {

struct Nearest {
  double d2 = std::numeric_limits<double>::infinity();
  DVec3 point{std::numeric_limits<double>::quiet_NaN()};
  double u = std::numeric_limits<double>::quiet_NaN(), v = u;
  DVec3 normal{std::numeric_limits<double>::quiet_NaN()};
  int32_t instance = -1, mesh = -1, prim = -1;
};

// Squared distance from q to a box, lowered by a relative 1e-12 so that rounding never prunes a
// box holding a triangle the double test would find nearer (box corners are floats, exact in
// double; the bound covers the three rounded squares and their sum).
double box_distance2(const DVec3& lo, const DVec3& hi, const DVec3& q) {
  const DVec3 d = glm::max(glm::max(lo - q, q - hi), DVec3(0.0));
  return glm::dot(d, d) * (1.0 - 1e-12);
}

// The world box of an object-space box under an affine map (centre and half extent: the extent
// maps through |M|), widened by a relative 1e-12 for the double rounding of the map.
void world_box(const glm::dmat4& m, const float* b, DVec3& lo, DVec3& hi) {
  const DVec3 blo(b[0], b[1], b[2]), bhi(b[3], b[4], b[5]);
  const DVec3 c = 0.5 * (blo + bhi), e = 0.5 * (bhi - blo);
  const glm::dmat3 l(m);
  const DVec3 wc = l * c + DVec3(m[3]);
  const glm::dmat3 abs_l(glm::abs(l[0]), glm::abs(l[1]), glm::abs(l[2]));
  const DVec3 we = abs_l * e;
  const DVec3 pad = 1e-12 * (glm::abs(wc) + we);
  lo = wc - we - pad;
  hi = wc + we + pad;
}

void search_instance(const Scene& scene, uint32_t id, const DVec3& q, Nearest& best) {
  const Instance& inst = scene.instance(id);
  const Mesh& mesh = scene.mesh(inst.mesh);
  const TriangleBlock* blocks = mesh.blocks().data();
  const glm::dmat4 m(inst.to_world);
  auto to_world = [&](const Vec3& p) { return inst.identity ? DVec3(p) : DVec3(m * glm::dvec4(DVec3(p), 1.0)); };
  auto box_d2 = [&](const float* b) {
    if (inst.identity) return box_distance2(DVec3(b[0], b[1], b[2]), DVec3(b[3], b[4], b[5]), q);
    DVec3 lo, hi;
    world_box(m, b, lo, hi);
    return box_distance2(lo, hi, q);
  };
  walk_nearest(
      mesh.wide_bvh(), box_d2,
      [&](uint32_t first, uint32_t count, double& best2) {
        const uint32_t stop = first + (count + kBlockWidth - 1) / kBlockWidth;
        for (uint32_t k = first; k < stop; ++k)
          for (int lane = 0; lane < kBlockWidth; ++lane) {
            const uint32_t prim = blocks[k].prim[lane];
            if (prim == kNoTriangle) continue;
            // The block's copy of the triangle's vertices (in its order: the same floats as
            // vertices[triangles[prim][i]]), so no further dependent reads.
            const DVec3 a = to_world(blocks[k].vertex(lane, 0)), b = to_world(blocks[k].vertex(lane, 1)),
                        c = to_world(blocks[k].vertex(lane, 2));
            // The triangle's own box first: a wide leaf is a whole collapsed subtree (up to a block),
            // whose triangles' boxes prune most of its exact tests (5-10 % of the query at 82K-1.3M).
            if (!(box_distance2(glm::min(glm::min(a, b), c), glm::max(glm::max(a, b), c), q) < best2)) continue;
            const TriangleClosest tc = closest_on_triangle(q, a, b, c);
            const DVec3 d = q - tc.point;
            const double d2 = glm::dot(d, d);
            if (d2 < best2 || (d2 == best2 && best.prim < 0)) {
              best2 = d2;
              best.point = tc.point;
              best.u = tc.u;
              best.v = tc.v;
              best.normal = glm::normalize(glm::cross(b - a, c - a));
              best.instance = int32_t(id);
              best.mesh = int32_t(inst.mesh);
              best.prim = int32_t(prim);
            }
          }
      },
      best.d2);
}

Nearest nearest(const Scene& scene, const DVec3& q) {
  Nearest best;
  const Bvh& top = scene.top_level();
  walk_nearest(
      top, [&](const float* b) { return box_distance2(DVec3(b[0], b[1], b[2]), DVec3(b[3], b[4], b[5]), q); },
      [&](uint32_t first, uint32_t count, double&) {
        for (uint32_t k = first; k < first + count; ++k) search_instance(scene, top.prim_ids[k], q, best);
      },
      best.d2);
  return best;
}

template <class Body>
void for_each_point(size_t count, int threads, Body&& body) {
  run_with_threads(threads, [&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 64), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i) body(i);
    });
  });
}

DVec3 point_at(const float* points, size_t i) { return {points[3 * i], points[3 * i + 1], points[3 * i + 2]}; }

}  // namespace

void compute_closest_points(const Scene& scene, const float* points, size_t count, const ClosestBatch& out,
                            int threads) {
  scene.check_committed();
  check_threads(threads);
  check_points(points, count);
  for_each_point(count, threads, [&](size_t i) {
    const Nearest n = nearest(scene, point_at(points, i));
    for (int a = 0; a < 3; ++a) {
      out.points[3 * i + a] = float(n.point[a]);
      out.normal[3 * i + a] = float(n.normal[a]);
    }
    out.distance[i] = float(std::sqrt(n.d2));
    out.u[i] = float(n.u);
    out.v[i] = float(n.v);
    out.mesh[i] = n.mesh;
    out.instance[i] = n.instance;
    out.prim[i] = n.prim;
  });
}

void compute_distance(const Scene& scene, const float* points, size_t count, float* distance, bool signed_distance,
                      int threads) {
  scene.check_committed();
  check_threads(threads);
  check_points(points, count);
  for_each_point(count, threads,
                 [&](size_t i) { distance[i] = float(std::sqrt(nearest(scene, point_at(points, i)).d2)); });
  if (!signed_distance) return;
  std::vector<uint8_t> inside(count);
  compute_occupancy(scene, points, count, inside.data(), threads);
  for (size_t i = 0; i < count; ++i)
    if (inside[i] && distance[i] != 0.0f) distance[i] = -distance[i];
}

}  // namespace toyrt::queries
