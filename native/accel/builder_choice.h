// Which builder a mesh gets when the caller says "auto": the one whose build plus the tracing to
// come costs least ("model no more than a scene needs"). The SAH tree traces faster; the LBVH
// builds faster. With n triangles and R rays expected through the mesh:
//   cost(SAH)  = kSahBuildNs  * n + R * kTraceNs
//   cost(LBVH) = kLbvhBuildNs * n + R * kTraceNs * kLbvhTraceFactor
// so the LBVH wins when R < n * (kSahBuildNs - kLbvhBuildNs) / (kTraceNs * (kLbvhTraceFactor - 1)).
// The constants are per-core-agnostic ratios measured by `make bench-lbvh` on the benchmark
// meshes (docs/lbvh.md), which also checks that the choice lands within 10 % of the better total.
#pragma once

#include <cstddef>

namespace toyrt {

enum class BuilderKind { Auto, Sah, Lbvh };

struct BuilderCostModel {
  double sah_build_ns = 500.0;    // per triangle, binned SAH with TBB (measured 450-540 at 1M, 2 cores)
  double lbvh_build_ns = 170.0;   // per triangle, LBVH kernels on PoCL (measured 150-200 at 1M, 2 cores)
  double trace_ns = 250.0;        // per ray through a SAH tree (primary, diffuse and shadow mixed, 2 cores)
  double lbvh_trace_factor = 1.3; // an LBVH tree's ray cost relative to SAH's (measured 1.2-1.4)

  // expected_rays < 0: unknown, which keeps the SAH tree (the faster to trace).
  BuilderKind choose(size_t triangles, double expected_rays) const {
    if (expected_rays < 0.0) return BuilderKind::Sah;
    const double sah = sah_build_ns * double(triangles) + expected_rays * trace_ns;
    const double lbvh = lbvh_build_ns * double(triangles) + expected_rays * trace_ns * lbvh_trace_factor;
    return lbvh < sah ? BuilderKind::Lbvh : BuilderKind::Sah;
  }
};

}  // namespace toyrt
