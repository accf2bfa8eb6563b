// The one entry point to every BVH builder: the top level, tests and benchmarks call build_bvh()
// with a BuilderKind, a mesh calls build_wide_bvh() (the same builders, ending in the traced
// layout), and nothing else names a builder's own function to build a scene. Adding a builder =
// its own accel/<x>_builder.{h,cpp} (as binned_sah_builder and lbvh_builder) + its entry in this
// pair: a BuilderKind value and its settings in BuilderSettings here, one row of the table in
// builder.cpp (name, kind, binary and wide build functions). The scene's CommitOptions inherit
// BuilderSettings, so the scene needs no edit.
//
// "auto" picks, per build, the builder whose build plus the tracing to come costs least ("model
// no more than a scene needs"). The SAH tree traces faster; the LBVH builds faster. With n
// primitives and R rays expected through them:
//   cost(SAH)  = kSahBuildNs  * n + R * kTraceNs
//   cost(LBVH) = kLbvhBuildNs * n + R * kTraceNs * kLbvhTraceFactor
// so the LBVH wins when R < n * (kSahBuildNs - kLbvhBuildNs) / (kTraceNs * (kLbvhTraceFactor - 1)).
// Break-even: about 11 rays per triangle. The constants were measured on this project's
// machines; `make bench-lbvh` reports how close the choice lands to the better total.
#pragma once

#include "accel/binned_sah_builder.h"
#include "accel/lbvh_builder.h"

#include <cstddef>
#include <string>

namespace toyrt {

enum class BuilderKind { Auto, Sah, Lbvh };

// Parses "auto", "sah", "lbvh"; throws std::invalid_argument on anything else.
BuilderKind parse_builder(const std::string& name);
const char* builder_name(BuilderKind kind);

struct BuilderCostModel {
  // Measured by `make bench-lbvh` on 2 cores (docs/lbvh-bench.md), 10K to 4M triangles. Both
  // builds have since got faster (2026-12-05: SAH about 200 ns a triangle at 1M, the host LBVH
  // about 30, the kernels 70); the ratio that decides is much the same, and auto still lands on
  // the better total in every row there, so these stay until a workload shows a wrong pick.
  double sah_build_ns = 450.0;     // per triangle, binned SAH with TBB (420-750)
  double lbvh_build_ns = 150.0;    // per triangle, LBVH kernels on PoCL (125-260)
  double trace_ns = 130.0;         // per ray through a SAH tree, primary/diffuse/shadow mixed (100-230)
  double lbvh_trace_factor = 1.2;  // an LBVH tree's ray cost relative to SAH's (1.06-1.28)

  // expected_rays < 0: unknown, which keeps the SAH tree (the faster to trace).
  BuilderKind choose(size_t triangles, double expected_rays) const {
    if (expected_rays < 0.0) return BuilderKind::Sah;
    const double sah = sah_build_ns * double(triangles) + expected_rays * trace_ns;
    const double lbvh = lbvh_build_ns * double(triangles) + expected_rays * trace_ns * lbvh_trace_factor;
    return lbvh < sah ? BuilderKind::Lbvh : BuilderKind::Sah;
  }
};

// Every builder's settings; each builder reads its own part. A new builder's settings go here
// (and reach Scene::commit through CommitOptions, which inherits them).
struct BuilderSettings {
  BinnedSahConfig sah;
  LbvhConfig lbvh;
  BuilderCostModel cost_model;
};

struct BuildConfig : BuilderSettings {
  // Rays the caller expects to trace through these primitives, for Auto; < 0: unknown (Auto
  // keeps the SAH builder).
  double expected_rays = -1.0;
  // The caller bounds each leaf as it lays the leaves out (Mesh::finish reads every triangle's
  // vertices then anyway), so a builder that would read the primitives' boxes again, at random,
  // only for the leaves (the host LBVH) may leave the boxes and the slot order to
  // complete_wide_boxes(): WideBuild::boxes_pending says it did.
  bool leaf_boxes_by_caller = false;
};

struct BuildStats {
  BuilderKind used = BuilderKind::Sah;  // the builder that made the tree (never Auto)
  double lbvh_compile_ms = 0.0;         // OpenCL compilation inside this build (first LBVH build of the process)
  // Set when the LBVH could not run (no OpenCL device, kernel build failure) and the SAH builder
  // stood in.
  std::string warning;
};

// Builds over `count` primitives given their boxes, on the calling thread's TBB arena. Builders
// take a primitive's centre to be its box's (BBox::center) and compute it where they need it,
// so no caller writes an array of centres. Auto resolves with config.cost_model for `count`
// primitives; an LBVH build that cannot run falls back to SAH and says so in stats->warning. SAH
// builds throw BuildCancelled when config.sah.cancel is set.
Bvh build_bvh(BuilderKind kind, const BBox* prim_bounds, size_t count, const BuildConfig& config = {},
              BuildStats* stats = nullptr);
// The same build, ending in the traced layout: wide nodes whose leaves hold subtrees of up to
// leaf_size primitives (collapse() of the binary tree; the LBVH collapses its kernels' tree in
// place and never writes a binary Bvh). What a mesh commits.
WideBuild build_wide_bvh(BuilderKind kind, const BBox* prim_bounds, size_t count, uint32_t leaf_size,
                         const BuildConfig& config = {}, BuildStats* stats = nullptr);

}  // namespace toyrt
