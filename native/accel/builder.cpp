#include "accel/builder.h"

#include "core/uninitialized_array.h"
#include "opencl/device.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <iterator>
#include <stdexcept>

namespace toyrt {

namespace {

Bvh build_sah(const BBox* bounds, const Vec3* centers, size_t count, const BuildConfig& config, BuildStats& st) {
  st.used = BuilderKind::Sah;
  return build_binned_sah(bounds, centers, count, config.sah);
}

// An LBVH build that cannot run (no OpenCL device, kernel build failure) falls back to SAH.
Bvh build_linear(const BBox* bounds, const Vec3* centers, size_t count, const BuildConfig& config, BuildStats& st) {
  try {
    UninitializedArray<Vec3> made;  // the boxes' centres, when the caller left them out
    if (!centers) {
      made = UninitializedArray<Vec3>(count);
      tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 16384), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) made.emplace(i, bounds[i].center());
      });
      centers = made.data();
    }
    LbvhStats lbvh_stats;
    Bvh bvh = build_lbvh(bounds, centers, count, config.lbvh, &lbvh_stats);
    st.used = BuilderKind::Lbvh;
    st.lbvh_compile_ms = lbvh_stats.compile_ms;
    return bvh;
  } catch (const opencl::OpenClError& e) {
    st.warning = std::string("LBVH builder unavailable, using the SAH builder instead: ") + e.what();
  }
  return build_sah(bounds, centers, count, config, st);
}

struct BuilderEntry {
  const char* name;
  BuilderKind kind;
  // Null for Auto, which build_bvh resolves to another entry first.
  Bvh (*build)(const BBox* bounds, const Vec3* centers, size_t count, const BuildConfig& config, BuildStats& st);
};
// The one table of builders: a new builder adds its row here.
constexpr BuilderEntry kBuilders[] = {{"auto", BuilderKind::Auto, nullptr},
                                      {"sah", BuilderKind::Sah, build_sah},
                                      {"lbvh", BuilderKind::Lbvh, build_linear}};

}  // namespace

BuilderKind parse_builder(const std::string& name) {
  for (const BuilderEntry& b : kBuilders)
    if (name == b.name) return b.kind;
  std::string names;  // "'auto', 'sah' or 'lbvh'"
  const size_t n = std::size(kBuilders);
  for (size_t i = 0; i < n; ++i)
    names += std::string(i == 0 ? "" : i + 1 == n ? " or " : ", ") + "'" + kBuilders[i].name + "'";
  throw std::invalid_argument("unknown builder '" + name + "': expected " + names);
}

const char* builder_name(BuilderKind kind) {
  for (const BuilderEntry& b : kBuilders)
    if (kind == b.kind) return b.name;
  return "?";
}

Bvh build_bvh(BuilderKind kind, const BBox* prim_bounds, const Vec3* prim_centers, size_t count,
              const BuildConfig& config, BuildStats* stats) {
  BuildStats local;
  BuildStats& st = stats ? *stats : local;
  st = BuildStats{};
  if (kind == BuilderKind::Auto) kind = config.cost_model.choose(count, config.expected_rays);
  for (const BuilderEntry& b : kBuilders)
    if (b.kind == kind && b.build) return b.build(prim_bounds, prim_centers, count, config, st);
  throw std::invalid_argument("build_bvh: unknown builder kind");
}

}  // namespace toyrt
