// Multiscatter GGX glass as Cycles 4.0+ renders it: the single-scatter glass lobe scaled by 1 / E,
// with E a directional albedo (reflection plus transmission) at wo: the energy a white interface
// loses to masking is put back, the lobe's shape and sampling staying single-scatter (Kulla and
// Conty 2017; a tinted glass keeps part of it, multiscatter_glass_factor).
//
// Which E: Cycles reads it from precomputed 16^3 tables over (sqrt(alpha), cos_o, z), z =
// sqrt((n - 1) / (n + 1)) of the IOR n >= 1 (an inverse table inside), trilinearly. Their
// entries count what a sampler returned when they were made: inside the glass that includes
// refractions landing back on wo's side, which the lobe never returns, so E there is up to 20-34 %
// above the lobe's own albedo at grazing cos_o (checked against the tables' values at grid points:
// tests/native/dielectric_test.cpp). Following the tables, not the lobe, is what renders as Cycles
// does. A material's roughness and IOR are fixed, so its E is made once, when the material is:
// cycles_table_albedo at the four (roughness, z) grid corners around it, at Cycles' 16 cosines on
// each side (entering: eta = ior; leaving: 1 / ior), mixed as the trilinear read mixes them.
#pragma once

#include "materials/dielectric_lobe.h"

#include <array>
#include <cstdint>

namespace toyrt {

struct DielectricAlbedo {
  static constexpr int kMu = 15;  // cos_o at i / kMu, i = 0..kMu (Cycles' 16 points; 0: just above the horizon)
  std::array<float, kMu + 1> entering{}, leaving{};
  float entering_average = 1.0f, leaving_average = 1.0f;  // E_avg = 2 int E(mu) mu dmu on each side
};

// E as Cycles tabulates it for a white GGX glass of this alpha and eta (n_far / n_near) at
// cos_o: the mean over wo's visible normals of the sampled event's weight, reflection with
// probability F(wo.m) and weight (1 + L_o) / (1 + L_o + L_r) (0 below the horizon), refraction with
// 1 - F and (1 + L_o) / (1 + L_o + L(|cos_t|)) wherever it lands (L: Smith's Lambda); a 128 x 128
// grid of visible normals.
double cycles_table_albedo(float alpha, float eta, float cos_o);

// The material's table: height-correlated shadowing (4.0+) follows Cycles' tables (above); the
// separable kind, which no Blender version makes multiscatter, the lobe's own albedo by a
// 128 x 128 grid of visible normals, both of each normal's branches weighted by their Fresnel
// terms. About 0.3 s of one core per material, on all cores.
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

// What Cycles multiplies a multiscatter glass's single-scatter lobe by, for a glass whose
// transmission colour is fss (its Fss, "the transmissive tint makes up most of the colour"):
// 1 + F_ms (1 - E) / E, F_ms = fss E_avg / (1 - fss (1 - E_avg)) (materials/multiscatter.h), on
// both sides of the lobe. Exactly 1 / E for a white glass.
Vec3 multiscatter_glass_factor(const DielectricAlbedo& table, bool entering, float cos_o, const Vec3& fss);

}  // namespace toyrt
