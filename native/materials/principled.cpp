#include "materials/principled.h"

#include "materials/coat.h"
#include "materials/fresnel.h"
#include "materials/multiscatter.h"
#include "sampling/ggx_albedo.h"
#include "sampling/warp.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace toyrt {

Principled Principled::from_params(const Params& params) {
  Principled m;
  m.base = Lambert::from_params(params);
  const float roughness = float(params.number("roughness", m.roughness));
  if (!std::isfinite(roughness)) throw std::invalid_argument("principled: roughness must be finite");
  m.roughness = std::clamp(roughness, 0.0f, 1.0f);
  m.multiscatter = params.flag("multiscatter", m.multiscatter);
  m.layered = params.flag("layered", m.layered);
  m.burley = params.flag("burley", m.burley);
  m.shadowing = params.has("shadowing") ? shadowing_from_params(params) : m.shadowing;
  const double metallic = params.number("metallic", m.metallic);
  m.metallic = float(std::clamp(metallic, 0.0, 1.0));
  const float ior = float(params.number("ior", 1.45));  // every kind's default (the binding's)
  if (!(ior > 0.0f) || !std::isfinite(ior)) throw std::invalid_argument("principled: ior must be finite and > 0");
  const double transmission = params.number("transmission", 0.0);
  if (!std::isfinite(transmission)) throw std::invalid_argument("principled: transmission must be finite");
  m.transmission = float(std::clamp(transmission, 0.0, 1.0));
  const float glass_ior = float(params.positive("transmission_ior", ior));
  if (m.transmission > 0.0f) {
    // 3.x: the macro Fresnel pair, single scattering; 4.0+: Fresnel per microfacet, Multiscatter
    // GGX as the layer's.
    const DielectricRoughness rough{m.roughness, m.shadowing, MicrofacetDistribution::Ggx};
    m.glass = FresnelDielectric::make(glass_ior, rough, !m.layered, m.multiscatter && m.layered);
  }
  if (params.has("refraction_roughness")) {
    // 3.x's refraction closure has a roughness of its own (Transmission Roughness); 4.0+'s glass
    // is one closure with one roughness.
    if (m.layered) throw std::invalid_argument("principled: refraction_roughness needs layered False (Blender 3.x)");
    const double r = params.number("refraction_roughness", 0.0);
    if (!std::isfinite(r)) throw std::invalid_argument("principled: refraction_roughness must be finite");
    m.glass.transmit_roughness = float(std::clamp(r, 0.0, 1.0));
  }
  const float level = float(params.non_negative("specular_ior_level", 0.5));
  const Vec3 tint = params.color("specular_tint", Vec3(1.0f));
  // Specular IOR Level scales F0 (0.5: as the IOR gives it); the IOR with that F0 then shapes the
  // curve, on the same side of 1 as the given one.
  float f0 = f0_from_ior(ior);
  m.eta = ior;
  if (level != 0.5f) {
    f0 *= 2.0f * level;
    m.eta = ior_from_f0(f0);
    if (ior < 1.0f) m.eta = 1.0f / m.eta;
  }
  m.eta_f0 = f0_from_ior(m.eta);
  m.specular_tint = tint;
  m.f0 = glm::clamp(f0 * tint, Vec3(0.0f), Vec3(1.0f));
  // Fss: the same blend at the curve's average, F_avg(eta) remapped as the curve is.
  const float s = m.eta_f0 < 1.0f
                      ? std::clamp((fresnel_dielectric_average(m.eta) - m.eta_f0) / (1.0f - m.eta_f0), 0.0f, 1.0f)
                      : 1.0f;
  m.fss = glm::mix(m.f0, Vec3(1.0f), s);
  const double coat = params.number("coat_weight", 0.0);
  if (!std::isfinite(coat)) throw std::invalid_argument("principled: coat_weight must be finite");
  m.coat = float(std::clamp(coat, 0.0, 1.0));
  const double coat_roughness = params.number("coat_roughness", m.coat_roughness);
  if (!std::isfinite(coat_roughness)) throw std::invalid_argument("principled: coat_roughness must be finite");
  m.coat_roughness = float(std::clamp(coat_roughness, 0.0, 1.0));
  // Cycles takes max(coat_ior, 1): a coat below 1 would reflect as one above it.
  m.coat_eta = std::max(float(params.positive("coat_ior", m.coat_eta)), 1.0f);
  m.coat_f0 = f0_from_ior(m.coat_eta);
  m.coat_tint = params.color("coat_tint", m.coat_tint);
  return m;
}

namespace {

// A metal lobe of reflectance f0 (the base colour, clamped to [0, 1]) at normal incidence.
GlossyLobe metal_lobe(const Principled& m, const ShadingPoint& s, const Vec3& base_color) {
  GlossyLobe lobe = oriented_lobe(s, m.roughness, m.shadowing);
  lobe.f0 = glm::clamp(base_color, Vec3(0.0f), Vec3(1.0f));
  lobe.tint = Vec3(1.0f);
  if (!m.layered) {
    // 3.x: the dielectric curve of the Specular's IOR, blended from the base colour to white.
    lobe.fresnel = LobeFresnel::Dielectric;
    lobe.ior = m.eta;
    lobe.ior_f0 = m.eta_f0;
    return lobe;
  }
  // 4.0+: F82-tint (materials/fresnel.h), the tint at most 1.
  lobe.fresnel = LobeFresnel::F82Tint;
  lobe.f82_b = f82_tint_b(lobe.f0, glm::min(m.specular_tint, Vec3(1.0f)));
  if (m.multiscatter)
    lobe.tint = multiscatter_scale(m.roughness, lobe.wo.z,
                                   glm::clamp(f82_average(lobe.f0, lobe.f82_b), Vec3(0.0f), Vec3(1.0f)));
  return lobe;
}

// The dielectric layer of reflectance f0 at normal incidence, and the share of the base it leaves.
struct Layer {
  GlossyLobe lobe;
  float base = 1.0f;
};
Layer dielectric_layer(const Principled& m, const ShadingPoint& s, const Vec3& f0) {
  Layer layer{oriented_lobe(s, m.roughness, m.shadowing)};
  GlossyLobe& lobe = layer.lobe;
  const float mu = lobe.wo.z;
  lobe.fresnel = LobeFresnel::Dielectric;
  lobe.f0 = f0;
  lobe.ior = m.eta;
  lobe.ior_f0 = m.eta_f0;
  lobe.tint = m.multiscatter ? multiscatter_scale(m.roughness, mu, m.fss) : Vec3(1.0f);
  if (m.layered) {
    // The layer's albedo at wo: mix(F0, 1, s) with s the table's mean blend (Cycles' estimate),
    // times the multiscatter darkening its closure weight carries (the scale over 1 / E, Cycles'
    // energy_scale); the base gets the rest.
    const Vec3 layer_albedo = glm::mix(f0, Vec3(1.0f), ggx_fresnel_blend(m.roughness, mu, m.eta));
    const Vec3 covered = m.multiscatter ? lobe.tint * ggx_albedo(m.roughness, mu) * layer_albedo : layer_albedo;
    layer.base = std::clamp(1.0f - std::max({covered.x, covered.y, covered.z}), 0.0f, 1.0f);
  }
  return layer;
}

Scatter lobe_over(const GlossyLobe& lobe, const Vec3& f) {
  Scatter sc = Scatter::glossy_lobe(lobe);
  sc.f = f;
  return sc;
}

// 3.x: the base is Burley's diffuse about the shading normal on wo's side (as the integrator turns
// it), with the Principled Roughness.
Scatter burley_base(const Principled& m, const ShadingPoint& s, Scatter sc) {
  if (!m.burley) return sc;
  const Vec3 ng = glm::dot(s.ng, s.wo) > 0.0f ? s.ng : -s.ng;
  sc.burley = true;
  sc.retro = BurleyDiffuse{glm::dot(s.ns, ng) >= 0.0f ? s.ns : -s.ns, s.wo, m.roughness};
  return sc;
}

// The opaque parts (no glass). scale: on the base's weight (what the glass's draw leaves it);
// u: the lobe-choice number left for the metal's draw, or < 0: draw it here when needed.
Scatter opaque_scatter(const Principled& m, const ShadingPoint& s, const MaterialContext& ctx, const Vec3& albedo,
                       float scale, float u);
Scatter coated(const Principled& m, const ShadingPoint& s, const MaterialContext& ctx, const Vec3& albedo, float scale,
               float u);
Scatter clearcoated(const Principled& m, const ShadingPoint& s, const MaterialContext& ctx, const Vec3& albedo,
                    float scale, float u);

}  // namespace

Scatter scatter(const Principled& m, const ShadingPoint& s, const MaterialContext& ctx) {
  const Vec3 albedo = lambert_albedo(m.base, *ctx.textures, s.uv);
  if (m.metallic >= 1.0f && m.coat <= 0.0f) return Scatter::glossy_lobe(metal_lobe(m, s, albedo));
  const float glass = (1.0f - m.metallic) * m.transmission;
  if (glass <= 0.0f) {
    if (m.coat > 0.0f) return coated(m, s, ctx, albedo, 1.0f, -1.0f);
    return opaque_scatter(m, s, ctx, albedo, 1.0f, -1.0f);
  }
  // One of glass and opaque parts, each with probability its weight and then counted unweighted;
  // the base, always there in the opaque answer, carries (1 - transmission) of its weight over
  // the opaque draw's probability. The rest of the number, rescaled to [0, 1), is the metal's.
  const float u = ctx.lobe_uniform();
  if (u < glass) {
    // The glass's colours at this hit, as Cycles': 4.0+ tints the reflection by Specular Tint and
    // each transmission by the square root of the base colour (two interfaces of a closed object
    // give the base colour); 3.x tints the refraction by the base colour and leaves the
    // reflection white (its Specular Tint there, not modelled, is noted by the add-on).
    FresnelDielectric g = m.glass;
    const Vec3 base = glm::max(albedo, Vec3(0.0f));
    g.reflect_tint = m.layered ? m.specular_tint : Vec3(1.0f);
    g.transmit_tint = m.layered ? glm::sqrt(base) : base;
    return scatter(g, s, ctx);
  }
  const float rest = std::min((u - glass) / (1.0f - glass), 0x1.fffffep-1f);
  const float scale = (1.0f - m.transmission) / (1.0f - glass);
  if (m.coat > 0.0f) return coated(m, s, ctx, albedo, scale, rest);
  return opaque_scatter(m, s, ctx, albedo, scale, rest);
}

namespace {

Scatter opaque_scatter(const Principled& m, const ShadingPoint& s, const MaterialContext& ctx, const Vec3& albedo,
                       float scale, float u) {
  const float dielectric = 1.0f - m.metallic;
  // Given no glass (probability 1 - glass), the metal's probability is metallic / (1 - glass).
  const float metal_share = m.metallic / (1.0f - (1.0f - m.metallic) * m.transmission);
  const auto metal_drawn = [&] { return (u < 0.0f ? ctx.lobe_uniform() : u) < metal_share; };
  if (!m.layered) {
    // 3.x: one lobe whose F0 goes from the dielectric's to the base colour with Metallic, over
    // the base weighted 1 - Metallic.
    if (m.eta == 1.0f && m.metallic == 0.0f) return burley_base(m, s, Scatter::diffuse(scale * lambert_f(albedo)));
    const Vec3 f0 = glm::mix(m.f0, glm::clamp(albedo, Vec3(0.0f), Vec3(1.0f)), m.metallic);
    Scatter sc = burley_base(m, s, lobe_over(dielectric_layer(m, s, f0).lobe, scale * dielectric * lambert_f(albedo)));
    // The plain two-closure case (u < 0: neither glass nor clearcoat drew first): Cycles 3.x's
    // sample weights (render/closure_pick.h), the specular closure's average Fresnel colour at
    // the view (Cycles 3.x's interpolate_fresnel_color about the shading normal: the lobe's own
    // Fresnel for the microfacet normal z, whose mirror of wo is wo turned about z), against the
    // diffuse closure's average colour, (1 - Metallic) x the base colour.
    const float diffuse_weight = dielectric * (albedo.x + albedo.y + albedo.z) / 3.0f;
    if (u < 0.0f && diffuse_weight > 0.0f) {
      const Vec3& wo = sc.glossy.wo;
      const Vec3 reflect = lobe_fresnel(sc.glossy, Vec3(-wo.x, -wo.y, wo.z));
      const float layer_weight = (reflect.x + reflect.y + reflect.z) / 3.0f;
      if (layer_weight > 0.0f) sc.glossy_pick = layer_weight / (layer_weight + diffuse_weight);
    }
    return sc;
  }
  // 4.0+: Metallic mixes a metal with the dielectric layer over its base. The base is always
  // there; of the two lobes one is drawn with probability its weight (its value then counts
  // once, unweighted), which is what Cycles does when it picks a closure to continue with.
  if (m.eta == 1.0f) {
    if (m.metallic == 0.0f) return Scatter::diffuse(scale * lambert_f(albedo));
    if (metal_drawn()) return lobe_over(metal_lobe(m, s, albedo), scale * dielectric * lambert_f(albedo));
    return Scatter::diffuse(scale * dielectric * lambert_f(albedo));
  }
  const Layer layer = dielectric_layer(m, s, m.f0);
  const Vec3 f = scale * dielectric * layer.base * lambert_f(albedo);
  if (m.metallic > 0.0f && metal_drawn()) return lobe_over(metal_lobe(m, s, albedo), f);
  Scatter sc = lobe_over(layer.lobe, f);
  // The plain two-closure case (u < 0: neither glass nor coat drew first; no metal): Cycles'
  // sample weights, the layer's average of mix(F0, 1, s) times that of its closure weight's
  // multiscatter darkening E (1 + F_ms (1 - E) / E), the base's its average colour times the
  // share it keeps (render/closure_pick.h).
  if (u < 0.0f && m.metallic == 0.0f) {
    const float mu = layer.lobe.wo.z;
    const Vec3 reflect = glm::mix(m.f0, Vec3(1.0f), ggx_fresnel_blend(m.roughness, mu, m.eta));
    const Vec3 dark = m.multiscatter ? layer.lobe.tint * ggx_albedo(m.roughness, mu) : Vec3(1.0f);
    const float layer_weight = (reflect.x + reflect.y + reflect.z) * (dark.x + dark.y + dark.z) / 9.0f;
    const float base_weight = (f.x + f.y + f.z) / 3.0f * kPi / scale;
    if (layer_weight > 0.0f) sc.glossy_pick = layer_weight / (layer_weight + base_weight);
  }
  return sc;
}

// 4.0+'s coat over what opaque_scatter answers (Principled.h): the coat's lobe drawn with
// probability coat / 2 (its weight divided by that), else the answer below with its lobe divided
// by the rest; the layers below are attenuated and tinted on both draws, the diffuse part kept.
// 3.x's Clearcoat beside what opaque_scatter answers (materials/clearcoat.h), added as Cycles 3.x
// adds its closure, nothing below attenuated: its lobe, 0.25 x Clearcoat times the Fresnel term of
// IOR 1.5. Without a glass draw (u < 0) the closures are answered side by side, as Cycles mixes
// them (materials/closure_mixture.h). After the opaque share of a Transmission's glass draw (u >= 0:
// the rest of that number) the clearcoat is drawn with probability coat / 2 (its weight divided by
// that), else the answer below with its lobe divided by the rest; the diffuse part is kept on both
// draws. The glass draw carries no clearcoat, so the opaque draws carry it over their share.
Scatter clearcoated(const Principled& m, const ShadingPoint& s, const MaterialContext& ctx, const Vec3& albedo,
                    float scale, float u) {
  GlossyLobe coat = oriented_lobe(s, m.coat_roughness, GgxShadowing::Separable);
  coat.clearcoat = true;
  coat.fresnel = LobeFresnel::Dielectric;
  coat.f0 = Vec3(kClearcoatF0);
  coat.ior = kClearcoatIor;
  coat.ior_f0 = kClearcoatF0;
  if (u < 0.0f) {
    // No glass drew first: Cycles 3.x's three closures side by side (materials/closure_mixture.h),
    // each picked by its sample weight: the diffuse's (1 - Metallic) x the base's average colour,
    // the specular's and the clearcoat's their closure weights' average Fresnel colour at the view
    // (interpolate_fresnel_color about the shading normal: the lobe's Fresnel for the microfacet
    // normal z, whose mirror of wo is wo turned about z), the clearcoat's times 0.25 x Clearcoat.
    Scatter sc = opaque_scatter(m, s, ctx, albedo, scale, 1.0f);
    coat.tint = Vec3(0.25f * m.coat);
    const Vec3 mirror(-coat.wo.x, -coat.wo.y, coat.wo.z);
    const auto average = [](const Vec3& c) { return (c.x + c.y + c.z) / 3.0f; };
    Vec3 weights(0.0f, 0.0f, average(coat.tint * lobe_fresnel(coat, mirror)));
    if (sc.kind == Scatter::Kind::Glossy) weights.y = average(lobe_fresnel(sc.glossy, mirror));
    if (sc.f != Vec3(0.0f)) weights.x = (1.0f - m.metallic) * average(albedo);
    const float total = weights.x + weights.y + weights.z;
    if (!(total > 0.0f)) return sc;
    sc.kind = Scatter::Kind::Mixture;
    sc.second_glossy = coat;
    sc.closure_pick = weights / total;
    return sc;
  }
  const float p = 0.5f * m.coat;
  Scatter sc = opaque_scatter(m, s, ctx, albedo, scale, std::min(std::max(u - p, 0.0f) / (1.0f - p), 0x1.fffffep-1f));
  if (!(u < p)) {
    if (sc.kind == Scatter::Kind::Glossy) sc.glossy.tint /= 1.0f - p;
    return sc;
  }
  const float glass = (1.0f - m.metallic) * m.transmission;
  coat.tint = Vec3(0.25f * m.coat / (p * (1.0f - glass)));
  Scatter out =
      lobe_over(coat, sc.kind == Scatter::Kind::Diffuse || sc.kind == Scatter::Kind::Glossy ? sc.f : Vec3(0.0f));
  out.burley = sc.burley;
  out.retro = sc.retro;
  return out;
}

Scatter coated(const Principled& m, const ShadingPoint& s, const MaterialContext& ctx, const Vec3& albedo, float scale,
               float u) {
  if (!m.layered) return clearcoated(m, s, ctx, albedo, scale, u);
  const float v = u < 0.0f ? ctx.lobe_uniform() : u;
  GlossyLobe coat = oriented_lobe(s, m.coat_roughness, m.shadowing);
  coat.fresnel = LobeFresnel::Dielectric;
  coat.f0 = Vec3(m.coat_f0);
  coat.ior = m.coat_eta;
  coat.ior_f0 = m.coat_f0;
  // Cycles' layering (materials/coat.h): its estimate of the coat's albedo, energy compensation
  // included, taken off what lies below, and the tint along the refracted path.
  const CoatLayer layer = coat_layer(m.coat, m.coat_roughness, m.coat_eta, m.coat_f0, m.coat_tint, coat.wo.z);
  const Vec3& below = layer.below;
  const float p = 0.5f * m.coat;
  Scatter sc = opaque_scatter(m, s, ctx, albedo, scale, std::min((std::max(v - p, 0.0f)) / (1.0f - p), 0x1.fffffep-1f));
  sc.f *= below;
  if (v < p) {
    coat.tint = Vec3(layer.lobe_scale * m.coat / p);
    const Vec3 f = sc.kind == Scatter::Kind::Diffuse || sc.kind == Scatter::Kind::Glossy ? sc.f : Vec3(0.0f);
    Scatter out = lobe_over(coat, f);
    out.burley = false;
    return out;
  }
  if (sc.kind == Scatter::Kind::Glossy) sc.glossy.tint *= below / (1.0f - p);
  return sc;
}

}  // namespace

GlossyLobe principled_metal_lobe(const Principled& m, const ShadingPoint& s, const Vec3& base_color) {
  return metal_lobe(m, s, base_color);
}
GlossyLobe principled_specular_lobe(const Principled& m, const ShadingPoint& s) {
  return dielectric_layer(m, s, m.f0).lobe;
}

}  // namespace toyrt
