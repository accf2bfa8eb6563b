#include "accel/builder.h"

#include "opencl/device.h"

#include <stdexcept>

namespace toyrt {

namespace {
struct BuilderName {
  const char* name;
  BuilderKind kind;
};
// The parse table: a new builder adds its name here.
constexpr BuilderName kBuilderNames[] = {
    {"auto", BuilderKind::Auto}, {"sah", BuilderKind::Sah}, {"lbvh", BuilderKind::Lbvh}};
}  // namespace

BuilderKind parse_builder(const std::string& name) {
  for (const BuilderName& b : kBuilderNames)
    if (name == b.name) return b.kind;
  throw std::invalid_argument("unknown builder '" + name + "': expected 'auto', 'sah' or 'lbvh'");
}

const char* builder_name(BuilderKind kind) {
  for (const BuilderName& b : kBuilderNames)
    if (kind == b.kind) return b.name;
  return "?";
}

Bvh build_bvh(BuilderKind kind, const BBox* prim_bounds, const Vec3* prim_centers, size_t count,
              const BuildConfig& config, BuildStats* stats) {
  BuildStats local;
  BuildStats& st = stats ? *stats : local;
  st = BuildStats{};
  if (kind == BuilderKind::Auto) kind = config.cost_model.choose(count, config.expected_rays);
  switch (kind) {
    case BuilderKind::Lbvh:
      try {
        LbvhStats lbvh_stats;
        Bvh bvh = build_lbvh(prim_bounds, prim_centers, count, config.lbvh, &lbvh_stats);
        st.used = BuilderKind::Lbvh;
        st.lbvh_compile_ms = lbvh_stats.compile_ms;
        return bvh;
      } catch (const opencl::OpenClError& e) {
        st.warning = std::string("LBVH builder unavailable, using the SAH builder instead: ") + e.what();
      }
      [[fallthrough]];
    case BuilderKind::Sah:
    case BuilderKind::Auto:  // resolved above; listed so the switch names every kind
      st.used = BuilderKind::Sah;
      return build_binned_sah(prim_bounds, prim_centers, count, config.sah);
  }
  return {};
}

}  // namespace toyrt
