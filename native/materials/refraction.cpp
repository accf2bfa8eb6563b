#include "materials/refraction.h"

#include "materials/fresnel.h"
#include "materials/glossy.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace toyrt {
namespace {

float checked_ior(float ior) {
  if (!std::isfinite(ior) || ior <= 0.0f) throw std::invalid_argument("refraction: ior must be positive and finite");
  return ior;
}

// The interface seen from wo: normals turned to wo's side, and eta = n_i / n_t.
struct Interface {
  Vec3 ng, ns;  // unit, on wo's side
  float eta;
  bool entering;
};

Interface orient(const Vec3& wo, const Vec3& ng, const Vec3& ns, float ior) {
  Interface f;
  f.entering = glm::dot(wo, ng) > 0.0f;
  f.ng = glm::normalize(f.entering ? ng : -ng);
  Vec3 shading = glm::dot(ns, ng) < 0.0f ? -ns : ns;  // to ng's hemisphere first
  shading = glm::normalize(f.entering ? shading : -shading);
  f.ns = glm::dot(wo, shading) > 0.0f ? shading : f.ng;  // wo below ns's tangent plane: use ng
  f.eta = f.entering ? 1.0f / ior : ior;
  return f;
}

// One branch with normal n; `want_reflection` false means refract unless that is impossible.
SpecularSample scatter(const Vec3& wo, const Interface& f, const Vec3& n, bool want_reflection) {
  SpecularSample s;
  s.entering = f.entering;
  Vec3 wt;
  if (!want_reflection && refract(wo, n, f.eta, &wt)) {
    s.wi = wt;
  } else {
    s.reflected = true;
    s.total_internal_reflection = !want_reflection;
    s.wi = glm::normalize(reflect(wo, n));
  }
  return s;
}

SpecularSample scatter_checked(const Vec3& wo, const Interface& f, bool want_reflection) {
  SpecularSample s = scatter(wo, f, f.ns, want_reflection);
  // The shading normal's answer must leave on the right side of the real surface.
  const float side = glm::dot(s.wi, f.ng);
  if ((s.reflected && side <= 0.0f) || (!s.reflected && side >= 0.0f)) s = scatter(wo, f, f.ng, want_reflection);
  s.offset_normal = s.reflected ? f.ng : -f.ng;
  return s;
}

DielectricRoughness checked_roughness(DielectricRoughness rough) {
  if (!std::isfinite(rough.roughness)) throw std::invalid_argument("refraction: roughness must be finite");
  rough.roughness = std::clamp(rough.roughness, 0.0f, 1.0f);
  return rough;
}

DielectricRoughness roughness_from_params(const Params& params) {
  const std::string distribution = params.text("distribution", "ggx");
  if (distribution != "ggx" && distribution != "beckmann")
    throw std::invalid_argument("refraction: distribution must be 'ggx' or 'beckmann', not '" + distribution + "'");
  return {float(params.number("roughness", 0.0)), shadowing_from_params(params),
          distribution == "ggx" ? MicrofacetDistribution::Ggx : MicrofacetDistribution::Beckmann};
}

}  // namespace

PerfectRefraction PerfectRefraction::make(float ior, DielectricRoughness rough, const Vec3& color) {
  return {checked_ior(ior), checked_roughness(rough), color};
}
FresnelDielectric FresnelDielectric::make(float ior, DielectricRoughness rough, bool macro_fresnel, bool multiscatter) {
  FresnelDielectric m{checked_ior(ior), checked_roughness(rough), macro_fresnel, -1.0f, -1, Vec3(1.0f), Vec3(1.0f)};
  if (!multiscatter) return m;
  if (macro_fresnel || rough.distribution != MicrofacetDistribution::Ggx)
    throw std::invalid_argument("glass: multiscatter needs distribution 'ggx' and fresnel 'microfacet'");
  const float alpha = ggx_alpha(m.rough.roughness);
  if (alpha >= kDielectricMinAlpha) m.albedo = shared_dielectric_albedo(alpha, m.ior, m.rough.shadowing);
  return m;
}
PerfectRefraction PerfectRefraction::from_params(const Params& params) {
  return make(float(params.positive("ior", PerfectRefraction{}.ior)), roughness_from_params(params),
              params.color("color", Vec3(1.0f)));
}
FresnelDielectric FresnelDielectric::from_params(const Params& params) {
  const std::string fresnel = params.text("fresnel", "microfacet");
  if (fresnel != "microfacet" && fresnel != "macro")
    throw std::invalid_argument("glass: fresnel must be 'microfacet' or 'macro', not '" + fresnel + "'");
  FresnelDielectric m = make(float(params.positive("ior", FresnelDielectric{}.ior)), roughness_from_params(params),
                             fresnel == "macro", params.flag("multiscatter", false));
  m.reflect_tint = m.transmit_tint = params.color("color", Vec3(1.0f));
  return m;
}

bool rough_dielectric(const ShadingPoint& s, float ior, const DielectricRoughness& rough, DielectricKind kind,
                      DielectricLobe* lobe, float transmit_roughness) {
  const float alpha = ggx_alpha(rough.roughness);
  const bool own_transmission = transmit_roughness >= 0.0f;
  const float alpha_transmit = own_transmission ? ggx_alpha(transmit_roughness) : alpha;
  if (std::max(alpha, alpha_transmit) < kDielectricMinAlpha || std::abs(ior - 1.0f) < 1e-4f) return false;
  // The frame as a glossy lobe's (on wo's side, the geometric normal where wo is below the
  // shading normal's tangent plane); which side wo is on decides eta.
  const GlossyLobe g = oriented_lobe(s, rough.roughness, rough.shadowing);
  lobe->frame = g.frame;
  lobe->wo = g.wo;
  lobe->alpha = std::max(alpha, kDielectricMinAlpha);
  lobe->alpha_transmit = own_transmission ? std::max(alpha_transmit, kDielectricMinAlpha) : 0.0f;
  lobe->distribution = rough.distribution;
  lobe->shadowing = rough.shadowing;
  lobe->eta = glm::dot(s.wo, s.ng) > 0.0f ? ior : 1.0f / ior;
  lobe->kind = kind;
  lobe->fresnel_macro = kind == DielectricKind::Glass3x ? fresnel_dielectric(g.wo.z, lobe->eta) : 0.0f;
  // Cycles 3.4 and 4.0+ both evaluate transmission pairs no microfacet refracts
  // (materials/dielectric_lobe.h): light through a rough interface is counted as they count it.
  lobe->unchecked_refraction = true;
  lobe->tint = lobe->transmit_tint = Vec3(1.0f);
  return true;
}

SpecularSample sample(const PerfectRefraction& m, const Vec3& wo, const Vec3& ng, const Vec3& ns) {
  return scatter_checked(wo, orient(wo, ng, ns, m.ior), false);
}

SpecularSample sample(const FresnelDielectric& m, const Vec3& wo, const Vec3& ng, const Vec3& ns, float u) {
  const Interface f = orient(wo, ng, ns, m.ior);
  // fresnel_dielectric takes n_t / n_i, the inverse of the interface's eta.
  const float reflectance = fresnel_dielectric(glm::dot(wo, f.ns), 1.0f / f.eta);
  const bool reflect_branch = u < reflectance;
  SpecularSample s = scatter_checked(wo, f, reflect_branch);
  s.total_internal_reflection = reflectance >= 1.0f;
  s.probability = s.reflected ? reflectance : 1.0f - reflectance;
  if (s.reflected && !reflect_branch) s.probability = 1.0f;  // refraction impossible after the fallback
  return s;
}

int split(const FresnelDielectric& m, const Vec3& wo, const Vec3& ng, const Vec3& ns, SpecularSample out[2]) {
  // u = 0 takes reflection whenever F > 0; u = 1 takes refraction whenever it is possible.
  const SpecularSample r = sample(m, wo, ng, ns, 0.0f);
  const SpecularSample t = sample(m, wo, ng, ns, 1.0f);
  if (!r.reflected || t.reflected) {  // a single branch: F = 0, or no refraction
    out[0] = t.reflected ? t : r;
    out[0].probability = 1.0f;
    return 1;
  }
  out[0] = r;
  out[1] = t;
  out[1].probability = 1.0f - r.probability;  // exactly complementary, whatever rounding did
  return 2;
}

Scatter scatter(const PerfectRefraction& m, const ShadingPoint& s, const MaterialContext&) {
  DielectricLobe lobe;
  if (rough_dielectric(s, m.ior, m.rough, DielectricKind::Refraction, &lobe)) {
    lobe.tint = lobe.transmit_tint = m.color;
    return Scatter::dielectric_lobe(lobe);
  }
  SpecularSample b = sample(m, s.wo, s.ng, s.ns);
  b.weight = m.color;
  return Scatter::specular(b);
}

Scatter scatter(const FresnelDielectric& m, const ShadingPoint& s, const MaterialContext& ctx) {
  DielectricLobe lobe;
  if (rough_dielectric(s, m.ior, m.rough, m.macro_fresnel ? DielectricKind::Glass3x : DielectricKind::Glass, &lobe,
                       m.macro_fresnel ? m.transmit_roughness : -1.0f)) {
    const Vec3 scale = m.albedo >= 0
                           ? multiscatter_glass_factor(dielectric_albedo_table(m.albedo), glm::dot(s.wo, s.ng) > 0.0f,
                                                       lobe.wo.z, m.transmit_tint)
                           : Vec3(1.0f);
    lobe.tint = m.reflect_tint * scale;
    lobe.transmit_tint = m.transmit_tint * scale;
    return Scatter::dielectric_lobe(lobe);
  }
  if (!ctx.split) {
    SpecularSample b = sample(m, s.wo, s.ng, s.ns, ctx.uniform());
    b.weight = b.reflected ? m.reflect_tint : m.transmit_tint;
    return Scatter::specular(b);
  }
  // Splitting: both branches, each weighted by its Fresnel term, instead of choosing one with
  // that probability. A light seen in a reflection with F = 0.04 is otherwise an all-or-nothing
  // sample in 4 % of the paths, the largest variance in a glass scene (docs/render.md).
  Scatter out;
  out.kind = Scatter::Kind::Split;
  out.count = split(m, s.wo, s.ng, s.ns, out.branches);
  for (int b = 0; b < out.count; ++b)
    out.branches[b].weight = out.branches[b].reflected ? m.reflect_tint : m.transmit_tint;
  return out;
}

}  // namespace toyrt
