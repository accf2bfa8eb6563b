#include "oracle_compare.h"

#include <cmath>
#include <limits>
#include <sstream>

namespace toyrt::testing {

std::string Agreement::summary() const {
  std::ostringstream s;
  s << rays << " rays: " << both_hit << " both hit, " << both_miss << " both miss; TOYRT errors: " << toyrt_misses
    << " misses, " << toyrt_false_hits << " false hits, " << t_mismatches << " t (max rel " << max_t_rel_error << "), "
    << uv_mismatches << " uv, " << occluded_mismatches << " occluded; " << grazing
    << " grazing; Embree errors: " << embree_leaks << " leaks, " << embree_false_hits << " false hits, "
    << embree_t_errors << " t (max rel " << max_t_rel_error_embree << ")";
  return s.str();
}

std::string OcclusionAgreement::summary() const {
  std::ostringstream s;
  s << rays << " shadow rays, " << blocked << " blocked: " << agree << " agree, TOYRT wrong " << toyrt_wrong
    << ", grazing " << grazing << ", Embree wrong " << embree_wrong;
  return s.str();
}

Crossing cross_in_double(const MeshData& mesh, int32_t prim, const Ray& ray) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  const Triangle& tri = mesh.triangles[size_t(prim)];
  const DVec3 p[3] = {DVec3(mesh.vertices[tri.x]), DVec3(mesh.vertices[tri.y]), DVec3(mesh.vertices[tri.z])};
  const DVec3 o(ray.org), d(ray.dir);
  const DVec3 n = glm::cross(p[1] - p[0], p[2] - p[0]);
  const double dn = glm::dot(d, n);
  Crossing c{kNaN, kNaN, kNaN, -std::numeric_limits<double>::infinity(), 0.0};
  if (dn == 0.0) return c;
  c.t = glm::dot(p[0] - o, n) / dn;
  const DVec3 x = o + c.t * d;
  const double area2 = glm::dot(n, n);
  // Barycentric of vertex i: signed area of the sub-triangle opposite it, over the whole.
  double b[3];
  for (int i = 0; i < 3; ++i) b[i] = glm::dot(glm::cross(p[(i + 1) % 3] - x, p[(i + 2) % 3] - x), n) / area2;
  c.u = b[1];
  c.v = b[2];
  // Distance to the edge opposite vertex i is b[i] times the triangle's height over that edge.
  c.margin = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    const double edge = glm::length(p[(i + 2) % 3] - p[(i + 1) % 3]);
    c.margin = std::min(c.margin, b[i] * std::sqrt(area2) / edge);
  }
  // A float evaluation in coordinates relative to the ray origin errs by a few ulps of the
  // distances involved (the hit distance and the triangle's size); seen in the triangle's plane
  // the error grows as 1 / cos(incidence).
  const double cos_incidence = std::fabs(dn) / (glm::length(d) * std::sqrt(area2));
  const double size = std::max({glm::length(p[1] - p[0]), glm::length(p[2] - p[1]), glm::length(p[0] - p[2])});
  const double magnitude = glm::length(x - o) + size;
  c.band = 8.0 * std::numeric_limits<float>::epsilon() * magnitude / std::max(cos_incidence, 1e-3);
  return c;
}

Verdict judge(const MeshData& mesh, const Hit& hit, const Ray& ray) {
  const Crossing c = cross_in_double(mesh, hit.prim, ray);
  if (std::isnan(c.t)) return Verdict::Grazing;  // the ray lies in the triangle's plane
  const double dt = c.band / glm::length(DVec3(ray.dir));
  if (c.margin < -c.band || c.t < double(ray.tnear) - dt || c.t >= double(ray.tfar) + dt) return Verdict::NotCrossed;
  if (c.margin <= c.band || c.t < double(ray.tnear) + dt || c.t >= double(ray.tfar) - dt) return Verdict::Grazing;
  return Verdict::Crossed;
}

Agreement compare_with_embree(const Scene& scene, const EmbreeScene& embree, const MeshData& mesh,
                              const std::vector<Ray>& rays) {
  const BBox box = bounds_of(mesh);
  const double magnitude = std::max(glm::length(box.lo), glm::length(box.hi));
  Agreement a;
  a.rays = rays.size();
  for (const Ray& ray : rays) {
    const Hit mine = scene.intersect(ray), theirs = embree.intersect(ray);
    if (scene.occluded(ray) != mine.found()) ++a.occluded_mismatches;
    const double scale =
        std::max(std::fabs(double(mine.found() ? mine.t : theirs.t)) * glm::length(ray.dir), 1e-2 * magnitude) /
        glm::length(ray.dir);
    auto t_error = [&](const Hit& h) { return std::fabs(double(h.t) - cross_in_double(mesh, h.prim, ray).t) / scale; };
    if (!mine.found() && !theirs.found()) {
      ++a.both_miss;
      continue;
    }
    if (mine.found() && theirs.found()) ++a.both_hit;
    if (theirs.found()) {
      const double e = t_error(theirs);
      a.max_t_rel_error_embree = std::max(a.max_t_rel_error_embree, e);
      if (e > 1e-5) ++a.embree_t_errors;
    }
    if (mine.found()) {
      const Crossing c = cross_in_double(mesh, mine.prim, ray);
      const double e = std::fabs(double(mine.t) - c.t) / scale;
      a.max_t_rel_error = std::max(a.max_t_rel_error, e);
      if (e > 1e-5) ++a.t_mismatches;
      // The hit point from TOYRT's barycentrics against the true crossing point.
      const Triangle& tri = mesh.triangles[size_t(mine.prim)];
      const DVec3 p0(mesh.vertices[tri.x]), p1(mesh.vertices[tri.y]), p2(mesh.vertices[tri.z]);
      const DVec3 mine_p = (1.0 - mine.u - mine.v) * p0 + double(mine.u) * p1 + double(mine.v) * p2;
      const DVec3 true_p = (1.0 - c.u - c.v) * p0 + c.u * p1 + c.v * p2;
      if (glm::length(mine_p - true_p) > 1e-5 * scale * glm::length(ray.dir)) ++a.uv_mismatches;
    }
    // The same triangle, or one at the same true distance (neighbours sharing the edge the ray
    // meets): agreed. True distances, since Embree's own t can be off by more than 1e-5.
    if (mine.found() && theirs.found() &&
        (mine.prim == theirs.prim || std::fabs(cross_in_double(mesh, mine.prim, ray).t -
                                               cross_in_double(mesh, theirs.prim, ray).t) <= 1e-5 * scale))
      continue;
    // Otherwise the nearer report decides who is wrong.
    const bool mine_nearer = mine.found() && (!theirs.found() || mine.t < theirs.t);
    const Hit& nearer = mine_nearer ? mine : theirs;
    switch (judge(mesh, nearer, ray)) {
      case Verdict::Crossed:
        ++(mine_nearer ? a.embree_leaks : a.toyrt_misses);
        break;
      case Verdict::Grazing:
        ++a.grazing;
        break;
      case Verdict::NotCrossed:
        ++(mine_nearer ? a.toyrt_false_hits : a.embree_false_hits);
        break;
    }
  }
  return a;
}

OcclusionAgreement compare_occlusion_with_embree(const Scene& scene, const EmbreeScene& embree, const MeshData& mesh,
                                                 const std::vector<Ray>& rays) {
  OcclusionAgreement a;
  a.rays = rays.size();
  for (const Ray& ray : rays) {
    const bool mine = scene.occluded(ray), theirs = embree.occluded(ray);
    a.blocked += mine;
    if (mine == theirs) {
      ++a.agree;
      continue;
    }
    // The side that saw a blocker must show one the ray truly crosses.
    const Hit blocker = mine ? scene.intersect(ray) : embree.intersect(ray);
    const Verdict v = blocker.found() ? judge(mesh, blocker, ray) : Verdict::NotCrossed;
    if (v == Verdict::Grazing)
      ++a.grazing;
    else if ((v == Verdict::Crossed) == mine)
      ++a.embree_wrong;
    else
      ++a.toyrt_wrong;
  }
  return a;
}

}  // namespace toyrt::testing
