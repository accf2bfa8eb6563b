// Which builder a mesh gets when the caller says "auto": the one whose build plus the tracing to
// come costs least ("model no more than a scene needs"). The SAH tree traces faster; the LBVH
// builds faster. With n triangles and R rays expected through the mesh:
//   cost(SAH)  = kSahBuildNs  * n + R * kTraceNs
//   cost(LBVH) = kLbvhBuildNs * n + R * kTraceNs * kLbvhTraceFactor
// so the LBVH wins when R < n * (kSahBuildNs - kLbvhBuildNs) / (kTraceNs * (kLbvhTraceFactor - 1)).
// Break-even: about 11 rays per triangle. The constants were measured on this project's
// machines; `make bench-lbvh` reports how close the choice lands to the better total.
#pragma once

#include <cstddef>

namespace toyrt {

enum class BuilderKind { Auto, Sah, Lbvh };

struct BuilderCostModel {
  // Measured by `make bench-lbvh` on 2 cores (docs/lbvh-bench.md), 10K to 4M triangles:
  double sah_build_ns = 450.0;    // per triangle, binned SAH with TBB (420-750)
  double lbvh_build_ns = 150.0;   // per triangle, LBVH kernels on PoCL (125-260)
  double trace_ns = 130.0;        // per ray through a SAH tree, primary/diffuse/shadow mixed (100-230)
  double lbvh_trace_factor = 1.2; // an LBVH tree's ray cost relative to SAH's (1.06-1.28)

  // expected_rays < 0: unknown, which keeps the SAH tree (the faster to trace).
  BuilderKind choose(size_t triangles, double expected_rays) const {
    if (expected_rays < 0.0) return BuilderKind::Sah;
    const double sah = sah_build_ns * double(triangles) + expected_rays * trace_ns;
    const double lbvh = lbvh_build_ns * double(triangles) + expected_rays * trace_ns * lbvh_trace_factor;
    return lbvh < sah ? BuilderKind::Lbvh : BuilderKind::Sah;
  }
};

}  // namespace toyrt
