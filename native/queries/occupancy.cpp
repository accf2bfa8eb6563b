// compute_occupancy (queries/point_queries.h): an exact on-surface test, then the exact parity
// of one ray.
#include "core/parallel.h"
#include "queries/crossing_walk.h"
#include "queries/point_queries.h"
#include "queries/point_walk.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <stdexcept>
#include <string>

namespace toyrt::queries {
namespace {

// Whether q lies on the closed triangle (a, b, c), exactly in the model of exact_crossing.h
// (vertices translated to q in double): on the plane (zero volume), then inside or on the
// boundary of the triangle projected along its normal's dominant axis, where it is not flat.
bool on_triangle(const DVec3& q, const Vec3& p0, const Vec3& p1, const Vec3& p2) {
  const DVec3 a = DVec3(p0) - q, b = DVec3(p1) - q, c = DVec3(p2) - q;
  if (triple_sign(a, b, c) != 0) return false;
  const DVec3 n = glm::abs(glm::cross(DVec3(p1) - DVec3(p0), DVec3(p2) - DVec3(p0)));
  const int k = n.x > n.y ? (n.x > n.z ? 0 : 2) : (n.y > n.z ? 1 : 2);
  const int i = (k + 1) % 3, j = (k + 2) % 3;
  const int s0 = cross2_sign(a[i], a[j], b[i], b[j]), s1 = cross2_sign(b[i], b[j], c[i], c[j]),
            s2 = cross2_sign(c[i], c[j], a[i], a[j]);
  return !((s0 < 0 || s1 < 0 || s2 < 0) && (s0 > 0 || s1 > 0 || s2 > 0));
}

bool on_surface(const Mesh& mesh, const Vec3& q) {
  bool found = false;
  const DVec3 dq(q);
  const TriangleBlock* blocks = mesh.blocks().data();
  walk_containing(mesh.wide_bvh(), q, [&](uint32_t first, uint32_t count) {
    const uint32_t stop = first + (count + kBlockWidth - 1) / kBlockWidth;
    for (uint32_t k = first; k < stop && !found; ++k)
      for (int lane = 0; lane < kBlockWidth && !found; ++lane) {
        if (blocks[k].prim[lane] == kNoTriangle) continue;
        found = on_triangle(dq, blocks[k].vertex(lane, 0), blocks[k].vertex(lane, 1), blocks[k].vertex(lane, 2));
      }
    return found;
  });
  return found;
}

// The on-surface test and the parity in one walk: a point on a triangle lies in that
// triangle's box, which the ray from it reaches at t = 0, so the ray's walk meets every triangle
// the point may lie on; the float filter leaves the exact on-triangle test only the lanes whose
// plane may hold the point. A separate walk of the boxes containing the point cost 40 % of the
// query (docs/queries.md).
bool inside_instance(const Scene& scene, uint32_t id, const Vec3& q) {
  Ray ray;
  ray.org = q;
  ray.dir = Vec3(1.0f, 0.0f, 0.0f);  // any fixed direction: the tie-break makes every one exact
  ray.tnear = 0.0f;
  ray.tfar = kInfinity;
  if (!float_filter_usable()) {
    const Instance& inst = scene.instance(id);
    const Vec3 q_object = inst.identity ? q : Vec3(inst.to_object * glm::vec4(q, 1.0f));
    if (on_surface(scene.mesh(inst.mesh), q_object)) return true;
    bool odd = false;
    for_each_crossing_in_instance(scene, id, ray, [&](const Crossing& c, uint32_t) {
      if (c.t_sign > 0) odd = !odd;  // t = 0 would be on the surface, handled above
    });
    return odd;
  }
  bool odd = false, on = false;
  for_each_block_in_instance(scene, id, ray, [&](const ExactRay& r, const FloatFilterRay* fr, const TriangleBlock& b) {
    uint32_t plane = 0;
    for (uint32_t m = float_candidates(*fr, b, &plane); m; m &= m - 1) {
      const int lane = __builtin_ctz(m);
      Crossing c;
      if (exact_crossing(r, b.vertex(lane, 0), b.vertex(lane, 1), b.vertex(lane, 2), c) && c.t_sign > 0) odd = !odd;
    }
    for (; plane; plane &= plane - 1) {
      const int lane = __builtin_ctz(plane);
      if (on_triangle(r.org, b.vertex(lane, 0), b.vertex(lane, 1), b.vertex(lane, 2))) return on = true;
    }
    return false;
  });
  return on || odd;
}

}  // namespace

void check_points(const float* points, size_t count) {
  for (size_t i = 0; i < 3 * count; ++i)
    if (!std::isfinite(points[i]))
      throw std::invalid_argument("point " + std::to_string(i / 3) + " is not finite (NaN or inf)");
}

void compute_occupancy(const Scene& scene, const float* points, size_t count, uint8_t* inside, int threads) {
  scene.check_committed();
  check_threads(threads);
  check_points(points, count);
  const Bvh& top = scene.top_level();
  run_with_threads(threads, [&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 64), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i) {
        const Vec3 q(points[3 * i], points[3 * i + 1], points[3 * i + 2]);
        bool in = false;
        walk_containing(top, q, [&](uint32_t first, uint32_t n) {
          for (uint32_t k = first; k < first + n && !in; ++k) in = inside_instance(scene, top.prim_ids[k], q);
          return in;
        });
        inside[i] = in ? 1 : 0;
      }
    });
  });
}

}  // namespace toyrt::queries
