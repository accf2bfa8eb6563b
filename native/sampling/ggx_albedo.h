// How much light the GGX reflection lobe (height-correlated masking, Blender 4.0+) returns, as
// tables over roughness and the cosine of the outgoing direction: what Cycles 4.0+ reads to
// put back the energy single scattering loses (Multiscatter GGX, Kulla and Conty 2017) and to
// attenuate the Principled BSDF's diffuse base under its specular layer. The tables have
// Cycles' shapes and axes, so the same lookup gives the same answer:
//   E(roughness, cos_o)          directional albedo without Fresnel, 32 x 32;
//   E_avg(roughness)             its cosine-weighted average over cos_o, 32;
//   s(roughness, cos_o, z)       the mean over the visible normals of the dielectric Fresnel
//                                curve remapped to [0, 1], (F(wo.h) - F0) / (1 - F0), where
//                                z = sqrt((ior - 1) / (ior + 1)); 16 x 16 x 16. The lobe's
//                                albedo with Principled's Fresnel mix(F0', 1, s(wo.h)) is then
//                                about mix(F0', 1, s) (Cycles' estimate: it ignores E < 1).
// Roughness is Blender's (alpha = roughness^2); axes run linearly over [0, 1] with the ends
// clamped as Cycles' precomputation clamps them (roughness and cos_o at 1e-4, z at 0.99), and
// lookups interpolate linearly between entries.
//
// The numbers are ours: native/sampling/ggx_albedo_tables.inc is written by the
// ggx_albedo_tables program (tests/native/ggx_albedo_tables.cpp, `make tables`) from the
// estimators below, which integrate this project's own lobe (sampling/ggx.h) with stratified
// samples; tests/native/ggx_albedo_test.cpp checks entries against the estimators and against
// Cycles' published values.
#pragma once

#include <cstdint>

namespace toyrt {

inline constexpr int kGgxAlbedoSize = 32;        // E: roughness x cos_o; E_avg: roughness
inline constexpr int kGgxFresnelBlendSize = 16;  // s: roughness x cos_o x z

float ggx_albedo(float roughness, float cos_o);
float ggx_average_albedo(float roughness);
// ior >= 1 (the reflection off the denser side); ior < 1 reads as 1 / ior.
float ggx_fresnel_blend(float roughness, float cos_o, float ior);

// An n x n table over (roughness, cos_o) in [0, 1]^2, laid out as Cycles lays its tables (roughness
// fastest), read with the lookups above: linear between entries, the ends clamped, NaN as 0.
float lookup_2d(const float* table, int n, float roughness, float cos_o);

// The axes' values at entry i of n, as the tables were computed at them.
float ggx_table_roughness(int i, int n);
float ggx_table_cos(int i, int n);
float ggx_table_ior(int i, int n);  // from z = i / (n - 1), clamped to [1e-4, 0.99]

// The estimators the tables hold, with `n` x `n` stratified visible-normal samples (the
// average one also n cos_o strata). Deterministic.
double estimate_ggx_albedo(float roughness, float cos_o, int n);
double estimate_ggx_average_albedo(float roughness, int n);
double estimate_ggx_fresnel_blend(float roughness, float cos_o, float ior, int n);

}  // namespace toyrt
