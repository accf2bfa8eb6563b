// The Glossy Color pass at a camera ray's first hit, as Cycles writes it (kernel/film/data_passes.h
// sums, over the shader's glossy closures, what kernel/closure/bsdf.h's bsdf_albedo answers):
//   Blender 4.0+: the closure's weight times its Fresnel term's estimated albedo at wo
//     (bsdf_microfacet_estimate_albedo): 1 without a Fresnel term (the Glossy BSDF: its colour,
//     Multiscatter GGX's energy scale included, as Cycles puts it in the weight); for a dielectric
//     layer mix(F0, 1, s) with s the blend over the lobe's reflections of the IOR's curve
//     (sampling/ggx_albedo.h); for an F82-tint metal mix(F0, 1, s5) with s5 the same blend of
//     Schlick's (1 - cos)^5, without the F82 dip (Cycles leaves that term out of its estimate).
//   Blender 3.x: the closure's weight alone (surface_shader_glossy summed sc->weight): the Glossy
//     BSDF's colour, and 1 for the Principled's specular lobe whatever its Fresnel term.
// Glass (the Glass BSDF, colourless in TOYRT) counts its reflection: 3.x's closure weight F(cos_o)
// of the shading normal (Cycles 3.x split its Glass into a reflection closure of that weight and a
// refraction one); 4.0+ counts the glass closure with its reflection's estimated albedo,
// mix(F0, 1, s) entering and the Fresnel curve at cos_o leaving. The Refraction BSDF has none.
// A Principled 4.0+ between metal and dielectric draws one lobe per hit (materials/principled.h)
// with probability its weight, so the mean over samples is Cycles' weighted sum.
#pragma once

#include <cmath>

#include "materials/diffuse_glossy.h"
#include "materials/glossy.h"
#include "materials/glossy_lobe.h"
#include "materials/material.h"
#include "materials/principled.h"
#include "materials/refraction.h"
#include "render/aovs.h"

#include <vector>

namespace toyrt {

// The estimated albedo of a lobe's Fresnel term times its tint (Cycles 4.0+'s bsdf_albedo).
Vec3 lobe_albedo(const GlossyLobe& lobe);

// s5(roughness, cos_o): Cycles' ggx_gen_schlick_s read at its metals' z = 0.5 (near exponent 5;
// the .cpp says why not exactly), from a 16 x 16 table built once on first use.
float schlick_blend(float roughness, float cos_o);
// The mean over the GGX lobe's visible-normal reflections of (1 - cos_h)^exponent, 0 for those
// leaving below the surface, with n x n stratified samples (Cycles' precomputation). Deterministic.
double estimate_schlick_blend(float roughness, float cos_o, float exponent, int n);

// Multiscatter GGX (4.0+): TOYRT's tint holds the whole energy scale 1 + F_ms (1 - E) / E
// (materials/multiscatter.h), where Cycles' weight holds it divided by 1 + (1 - E) / E (the rest
// is its closure's energy_scale, outside the weight): the pass is the tint times E.
Vec3 lobe_weight_albedo(const GlossyLobe& lobe, bool multiscatter);

// What the pass holds for a material's glossy lobe (one overload per material with a lobe; the
// template for any other); Blender 3.x's Principled (the add-on sends layered False) its
// closure's weight, 1.
template <class M>
Vec3 glossy_pass_color(const M&, const GlossyLobe& lobe) {
  return lobe_albedo(lobe);
}
inline Vec3 glossy_pass_color(const Glossy& m, const GlossyLobe& lobe) {
  return lobe_weight_albedo(lobe, m.multiscatter);
}
inline Vec3 glossy_pass_color(const DiffuseGlossy& m, const GlossyLobe& lobe) {
  return lobe_weight_albedo(lobe, m.glossy.multiscatter);
}
inline Vec3 glossy_pass_color(const Principled& m, const GlossyLobe& lobe) {
  return m.layered ? lobe_weight_albedo(lobe, m.multiscatter) : Vec3(1.0f);
}

// Cycles 4.0+'s estimated reflectance of a dielectric interface at cos_o, eta = n_far / n_near.
float glass_reflectance(float roughness, float cos_o, float eta);

// The Glossy Color of a Glass BSDF (rough or specular) at a camera ray's first hit, 0 for every
// other material: out of line and outside the integrator (its place there, in the material
// dispatch or after it, cost a render without passes 0.08-0.24 % more instructions).
Vec3 glass_pass_color(const Material& m, const ShadingPoint& s);
// The reflection of one glass (the Glass BSDF's, or a Principled's glass with its colours).
Vec3 glass_reflection_color(const FresnelDielectric& m, const ShadingPoint& s);
// A Principled BSDF's whole Glossy Color at a hit of base colour `base_color`, as Cycles sums it
// over its closures: 4.0+ the coat's (its Fresnel's estimated albedo, energy share included),
// then the metal's, the glass's reflection and the specular layer's, each weighted by what the
// layers above leave; 3.x the specular closure's weight (1 - the glass's share) plus the glass's
// reflection closure (its share times the Fresnel term). Thin film (5.x) is not modelled, and
// neither rendered nor counted here.
Vec3 principled_pass_color(const Principled& m, const ShadingPoint& s, const Vec3& base_color);
// Completes a first hit's Glossy Color where the lobe the integrator drew is not the whole answer:
// adds a Glass BSDF's reflection; sets a Principled's with a coat or a glass to its whole sum.
// The renderer calls it in its loop with passes only, so a render without passes runs none of
// this (its loop and the integrator's stay as they were).
void add_layered_pass_color(const std::vector<Material>& materials, const std::vector<Texture>& textures,
                            FirstHit& hit);

}  // namespace toyrt
