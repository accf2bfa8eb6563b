// Multiscatter GGX glass as Cycles 4.0+ renders it: the single-scatter glass lobe scaled by 1 / E,
// with E its directional albedo (reflection plus transmission) at wo: the energy a white
// interface loses to masking is put back, the lobe's shape and sampling staying single-scatter
// (Kulla and Conty 2017 with a Fresnel average of 1, as materials/multiscatter.h for Fss = 1).
// A material's roughness and IOR are fixed, so its E is tabulated over cos_o once, when it is
// made, on both sides (entering: eta = ior; leaving: 1 / ior), from its own lobe.
#pragma once

#include "materials/dielectric_lobe.h"

#include <array>
#include <cstdint>

namespace toyrt {

struct DielectricAlbedo {
  static constexpr int kMu = 32;  // cos_o at i / kMu, i = 0..kMu (0: a cosine just above the horizon)
  std::array<float, kMu + 1> entering{}, leaving{};
};

// E of the 4.0+ Glass lobe (Fresnel per microfacet) by a 128 x 128 grid of visible
// normals at each cos_o, both of each normal's branches weighted by their Fresnel terms (within
// 1e-3 of a 2M-sample estimate; about 0.25 s per material).
DielectricAlbedo dielectric_albedo(float alpha, float ior, GgxShadowing shadowing);

// The same, computed once per (alpha, ior, shadowing) in the process and kept for its lifetime
// (thread-safe), named by a 32-bit id: materials hold the id, so the Material variant keeps its
// size and stays trivially copyable, as the integrator's Lambert path was measured with. -1 when
// the process already holds kMaxDielectricAlbedos tables (the material then scatters once).
inline constexpr int kMaxDielectricAlbedos = 4096;
int32_t shared_dielectric_albedo(float alpha, float ior, GgxShadowing shadowing);
const DielectricAlbedo& dielectric_albedo_table(int32_t id);  // id from shared_dielectric_albedo, >= 0

// 1 / E at cos_o (linear in cos_o between the table's points).
float multiscatter_glass_scale(const DielectricAlbedo& table, bool entering, float cos_o);

}  // namespace toyrt
