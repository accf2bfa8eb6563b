#include "accel/builder.h"

#include "accel/morton_wide_builder.h"
#include "opencl/device.h"

#include <iterator>
#include <stdexcept>

namespace toyrt {

namespace {

Bvh build_sah(const BBox* bounds, size_t count, const BuildConfig& config, BuildStats& st) {
  st.used = BuilderKind::Sah;
  return build_binned_sah(bounds, count, config.sah);
}

WideBuild build_sah_wide(const BBox* bounds, size_t count, uint32_t leaf_size, const BuildConfig& config,
                         BuildStats& st) {
  Bvh bvh = build_sah(bounds, count, config, st);
  WideBuild built{collapse(bvh, leaf_size), std::move(bvh.prim_ids)};
  return built;
}

// Runs an LBVH build, lbvh(stats). One that cannot run (no OpenCL device, kernel build failure)
// says why in st.warning and falls back to sah().
template <class Lbvh, class Sah>
auto lbvh_or_sah(BuildStats& st, Lbvh&& lbvh, Sah&& sah) {
  try {
    LbvhStats lbvh_stats;
    auto built = lbvh(&lbvh_stats);
    st.used = BuilderKind::Lbvh;
    st.lbvh_compile_ms = lbvh_stats.compile_ms;
    return built;
  } catch (const opencl::OpenClError& e) {
    st.warning = std::string("LBVH builder unavailable, using the SAH builder instead: ") + e.what();
  }
  return sah();
}

Bvh build_linear(const BBox* bounds, size_t count, const BuildConfig& config, BuildStats& st) {
  return lbvh_or_sah(
      st, [&](LbvhStats* stats) { return build_lbvh(bounds, count, config.lbvh, stats); },
      [&] { return build_sah(bounds, count, config, st); });
}

// Whether a mesh's LBVH runs the kernels (LbvhDevice::Auto: on an OpenCL GPU). On a CPU device
// (PoCL's) or with no OpenCL at all the host builds the same Morton order straight into wide
// nodes (build_morton_wide), 2-3x faster than the kernels and their collapse on the same cores
// (docs/lbvh.md); it makes 30-bit codes only, so 63-bit codes take the kernels.
bool lbvh_on_device(const LbvhConfig& config) {
  if (config.device == LbvhDevice::Host && config.bits != MortonBits::k30)
    throw std::invalid_argument("the host LBVH build makes 30-bit Morton codes only");
  if (config.device != LbvhDevice::Auto) return config.device == LbvhDevice::OpenCl;
  if (config.bits != MortonBits::k30) return true;
  try {
    return opencl::device().gpu;
  } catch (const opencl::OpenClError&) {
    return false;
  }
}

WideBuild build_linear_wide(const BBox* bounds, size_t count, uint32_t leaf_size, const BuildConfig& config,
                            BuildStats& st) {
  if (!lbvh_on_device(config.lbvh)) {
    st.used = BuilderKind::Lbvh;
    return build_morton_wide(bounds, count, leaf_size, !config.leaf_boxes_by_caller);
  }
  return lbvh_or_sah(
      st, [&](LbvhStats* stats) { return build_lbvh_wide(bounds, count, leaf_size, config.lbvh, stats); },
      [&] { return build_sah_wide(bounds, count, leaf_size, config, st); });
}

struct BuilderEntry {
  const char* name;
  BuilderKind kind;
  // Null for Auto, which build_bvh resolves to another entry first. `build` makes the binary
  // tree; `build_wide` the traced layout, by collapsing it or (the LBVH) straight from the
  // builder's own tree.
  Bvh (*build)(const BBox* bounds, size_t count, const BuildConfig& config, BuildStats& st);
  WideBuild (*build_wide)(const BBox* bounds, size_t count, uint32_t leaf_size, const BuildConfig& config,
                          BuildStats& st);
};
// The one table of builders: a new builder adds its row here.
constexpr BuilderEntry kBuilders[] = {{"auto", BuilderKind::Auto, nullptr, nullptr},
                                      {"sah", BuilderKind::Sah, build_sah, build_sah_wide},
                                      {"lbvh", BuilderKind::Lbvh, build_linear, build_linear_wide}};

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

namespace {
// The table row that builds `kind`, Auto resolved by the cost model; resets the stats.
const BuilderEntry& entry_for(BuilderKind kind, size_t count, const BuildConfig& config, BuildStats& st) {
  st = BuildStats{};
  if (kind == BuilderKind::Auto) kind = config.cost_model.choose(count, config.expected_rays);
  for (const BuilderEntry& b : kBuilders)
    if (b.kind == kind && b.build) return b;
  throw std::invalid_argument("build_bvh: unknown builder kind");
}
}  // namespace

Bvh build_bvh(BuilderKind kind, const BBox* prim_bounds, size_t count, const BuildConfig& config, BuildStats* stats) {
  BuildStats local;
  BuildStats& st = stats ? *stats : local;
  return entry_for(kind, count, config, st).build(prim_bounds, count, config, st);
}

WideBuild build_wide_bvh(BuilderKind kind, const BBox* prim_bounds, size_t count, uint32_t leaf_size,
                         const BuildConfig& config, BuildStats* stats) {
  BuildStats local;
  BuildStats& st = stats ? *stats : local;
  return entry_for(kind, count, config, st).build_wide(prim_bounds, count, leaf_size, config, st);
}

}  // namespace toyrt
