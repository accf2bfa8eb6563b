// Compares TOYRT's answers with Embree's on the same rays and classifies every disagreement by
// a double-precision test of the triangles involved, so a disagreement is charged to whichever
// side is wrong: the double-precision answer on the float geometry is the ground truth, Embree
// is the independent oracle for which triangle is nearest.
#pragma once

#include "embree_oracle.h"
#include "scene/scene.h"
#include "test_scenes.h"

#include <string>

namespace toyrt::testing {

// What the double-precision test says of a reported hit on one triangle.
enum class Verdict { Crossed, Grazing, NotCrossed };

struct Crossing {
  double t;       // distance along the ray to the triangle's plane, in units of |dir|
  double u, v;    // barycentrics of the crossing point (Embree's convention)
  double margin;  // signed distance from the crossing point to the nearest edge (inside > 0)
  double band;    // how close to an edge, or to tnear / tfar, float rounding can legitimately go
};
Crossing cross_in_double(const MeshData& mesh, int32_t prim, const Ray& ray);
Verdict judge(const MeshData& mesh, const Hit& hit, const Ray& ray);

struct Agreement {
  size_t rays = 0, both_hit = 0, both_miss = 0;
  // TOYRT's errors (tests expect zero):
  size_t toyrt_misses = 0;         // a nearer triangle the ray truly crosses was not reported
  size_t toyrt_false_hits = 0;     // a reported triangle the ray does not cross
  size_t t_mismatches = 0;         // t off the double-precision distance by more than 1e-5 relative
  size_t uv_mismatches = 0;        // hit point from (u, v) off the true one by more than 1e-5 relative
  size_t occluded_mismatches = 0;  // occluded() disagrees with intersect()
  // Rounding at a triangle's boundary: either answer is right.
  size_t grazing = 0;
  // Embree's errors, for the record:
  size_t embree_leaks = 0;       // Embree missed a nearer triangle the ray truly crosses
  size_t embree_false_hits = 0;  // Embree reported a triangle the ray does not cross (e.g. behind tnear)
  size_t embree_t_errors = 0;    // Embree's t off by more than 1e-5 relative
  double max_t_rel_error = 0.0, max_t_rel_error_embree = 0.0;
  std::string summary() const;
};

// scene must hold `mesh` as its only instance. Relative errors are taken against
// max(t |dir|, 1e-2 |coordinates|): float positions far from the origin carry an absolute error
// that no method can beat.
Agreement compare_with_embree(const Scene& scene, const EmbreeScene& embree, const MeshData& mesh,
                              const std::vector<Ray>& rays);

struct OcclusionAgreement {
  size_t rays = 0, blocked = 0, agree = 0;
  size_t toyrt_wrong = 0, grazing = 0, embree_wrong = 0;
  std::string summary() const;
};
OcclusionAgreement compare_occlusion_with_embree(const Scene& scene, const EmbreeScene& embree, const MeshData& mesh,
                                                 const std::vector<Ray>& rays);

}  // namespace toyrt::testing
