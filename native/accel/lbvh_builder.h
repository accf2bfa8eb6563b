// Linear BVH: primitives sorted along a Morton curve, the binary radix tree of their codes (Karras
// 2012) with its boxes. The OpenCL build runs kernels/lbvh.cl (on PoCL here), which builds the
// tree and its boxes bottom up in one pass (Apetrei 2014); the reference build runs Karras'
// top-down construction on the CPU with the same float operations, so the two agree node for
// node. Both end in the same binary Bvh the SAH builder makes (leaves of one
// primitive; collapse() gathers them into leaves of up to 8 triangles, one block, for tracing).
#pragma once

#include "accel/bvh.h"
#include "accel/lbvh_layout.h"
#include "accel/wide_bvh.h"

#include <string>
#include <vector>

namespace toyrt {

// Where a mesh's LBVH is built (build_wide_bvh): Auto runs the kernels on an OpenCL GPU and builds
// on the host otherwise (a CPU device such as PoCL's, or no OpenCL), where the host build is the
// faster (docs/lbvh.md); Host and OpenCl force one side, for tests and benchmarks.
enum class LbvhDevice { Auto, Host, OpenCl };

struct LbvhConfig {
  // 30-bit codes tell 1024 positions per axis apart, 63-bit codes two million; see docs/lbvh.md
  // for what the finer codes buy and cost. The host build makes 30-bit codes only.
  MortonBits bits = MortonBits::k30;
  LbvhDevice device = LbvhDevice::Auto;
};

struct LbvhStats {
  double compile_ms = 0.0;  // kernel compilation, paid once per process (0 after the first build)
  double build_ms = 0.0;    // uploads, kernels, download and conversion to Bvh
  std::string device;
  // Wall time of each stage, in pipeline order (the queue is drained between stages).
  std::vector<std::pair<std::string, double>> stages;
};

// The radix tree before conversion: n - 1 internal nodes by split position (node g splits
// between sorted leaves g and g + 1), the root's index, and the primitive order (sorted slot ->
// input index), with the sorted keys.
struct LbvhHierarchy {
  std::vector<LbvhNode> nodes;
  std::vector<uint32_t> values;
  std::vector<uint64_t> keys;
  int32_t root = 0;
};

// OpenCL build; throws opencl::OpenClError when there is no device or the kernels fail to build.
// The sorted keys are read back only when with_keys (tests compare them with the reference).
LbvhHierarchy build_lbvh_hierarchy_opencl(const BBox* prim_bounds, size_t count, const LbvhConfig& config,
                                          LbvhStats* stats = nullptr, bool with_keys = false);
// The same construction on the CPU, single-threaded: the reference the kernels are checked by.
LbvhHierarchy build_lbvh_hierarchy_reference(const BBox* prim_bounds, size_t count, const LbvhConfig& config);
// The flat Bvh of a hierarchy, laid out as the write_bvh_nodes kernel lays it out (children of
// internal node g at 1 + 2g; see lbvh_layout.h).
Bvh to_bvh(const LbvhHierarchy& h, const BBox* prim_bounds);

// OpenCL build straight to a Bvh (the flat nodes are written on the device).
Bvh build_lbvh(const BBox* prim_bounds, size_t count, const LbvhConfig& config = {}, LbvhStats* stats = nullptr);
// OpenCL build straight to the traced layout: the kernels' radix tree collapsed in place into
// wide nodes with leaves of up to leaf_size primitives (the flat nodes are never written). The
// same wide tree as collapse(build_lbvh(...), leaf_size).
WideBuild build_lbvh_wide(const BBox* prim_bounds, size_t count, uint32_t leaf_size, const LbvhConfig& config = {},
                          LbvhStats* stats = nullptr);
// The reference build straight to a Bvh.
Bvh build_lbvh_reference(const BBox* prim_bounds, size_t count, const LbvhConfig& config = {});

}  // namespace toyrt
