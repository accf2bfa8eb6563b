#include "render/glossy_color.h"

#include "materials/coat.h"
#include "materials/dielectric_albedo.h"
#include "materials/fresnel.h"
#include "materials/multiscatter.h"
#include "sampling/ggx.h"
#include "sampling/ggx_albedo.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace toyrt {

namespace {

constexpr int kSize = 16;    // Cycles' table size per axis
constexpr int kStrata = 32;  // per table entry: 32 x 32 stratified samples

using SchlickTable = std::array<float, kSize * kSize>;  // roughness fastest, then cos_o

// Cycles tabulates exponent e on an axis z = 1 / (0.2 e + 1) of 16 slices at z = k / 15 and reads
// its metals at z = 0.5, halfway between slices 7 and 8: the mean of exponents 40/7 and 35/8, not
// exponent 5 itself. The table holds that mean, so the pass is Cycles' own number.
SchlickTable build_table() {
  constexpr float kExponents[2] = {40.0f / 7.0f, 35.0f / 8.0f};
  SchlickTable t{};
  for (int j = 0; j < kSize; ++j)
    for (int i = 0; i < kSize; ++i) {
      const float rough = ggx_table_roughness(i, kSize), mu = ggx_table_cos(j, kSize);
      t[size_t(j * kSize + i)] = float(0.5 * (estimate_schlick_blend(rough, mu, kExponents[0], kStrata) +
                                              estimate_schlick_blend(rough, mu, kExponents[1], kStrata)));
    }
  return t;
}

}  // namespace

double estimate_schlick_blend(float roughness, float cos_o, float exponent, int n) {
  const float alpha = ggx_alpha(roughness);
  const Vec3 wo(std::sqrt(std::max(0.0f, 1.0f - cos_o * cos_o)), 0.0f, cos_o);
  double sum = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Vec2 u((float(i) + 0.5f) / float(n), (float(j) + 0.5f) / float(n));
      const Vec3 m = ggx_sample_visible_normal(alpha, wo, u);
      const float c = glm::dot(wo, m);
      const Vec3 wi = 2.0f * c * m - wo;
      if (!(wi.z >= kGgxMinCos)) continue;  // leaves below the surface: counts 0
      sum += std::pow(double(1.0f - std::clamp(c, 0.0f, 1.0f)), double(exponent));
    }
  return sum / (double(n) * double(n));
}

float schlick_blend(float roughness, float cos_o) {
  static const SchlickTable table = build_table();          // thread-safe, once, only when asked for
  return lookup_2d(table.data(), kSize, roughness, cos_o);  // as Cycles reads its tables
}

Vec3 lobe_albedo(const GlossyLobe& lobe) {
  // Cycles' roughness axis is sqrt(alpha): the roughness the lobe was made from.
  const float roughness = std::sqrt(lobe.alpha), mu = lobe.wo.z;
  switch (lobe.fresnel) {
    case LobeFresnel::None:
      return lobe.tint;
    case LobeFresnel::Dielectric:
      return lobe.tint * glm::mix(lobe.f0, Vec3(1.0f), ggx_fresnel_blend(roughness, mu, lobe.ior));
    case LobeFresnel::F82Tint:
      return lobe.tint * glm::mix(lobe.f0, Vec3(1.0f), schlick_blend(roughness, mu));
  }
  return Vec3(0.0f);
}

float glass_reflectance(float roughness, float cos_o, float eta) {
  if (eta > 1.0f) return glm::mix(f0_from_ior(eta), 1.0f, ggx_fresnel_blend(roughness, cos_o, eta));
  return fresnel_dielectric(cos_o, eta);  // from inside: Cycles takes the curve itself
}

Vec3 glass_reflection_color(const FresnelDielectric& m, const ShadingPoint& s) {
  // The lobe the material's scatter() makes there, or none where it is specular.
  DielectricLobe lobe;
  if (rough_dielectric(s, m.ior, m.rough, m.macro_fresnel ? DielectricKind::Glass3x : DielectricKind::Glass, &lobe))
    return m.reflect_tint *
           (m.macro_fresnel ? lobe.fresnel_macro : glass_reflectance(std::sqrt(lobe.alpha), lobe.wo.z, lobe.eta));
  const bool entering = glm::dot(s.ng, s.wo) > 0.0f;
  const Vec3 ng = entering ? s.ng : -s.ng;
  const Vec3 ns = glm::dot(s.ns, ng) >= 0.0f ? s.ns : -s.ns;
  const float cos_o = std::clamp(glm::dot(ns, s.wo), 0.0f, 1.0f), eta = entering ? m.ior : 1.0f / m.ior;
  return m.reflect_tint * (m.macro_fresnel ? fresnel_dielectric(cos_o, eta) : glass_reflectance(0.0f, cos_o, eta));
}

namespace {

// cos_o about the shading normal turned to wo's side of the surface (Cycles' sd->N).
float view_cosine(const ShadingPoint& s) {
  const Vec3 ng = glm::dot(s.ng, s.wo) > 0.0f ? s.ng : -s.ng;
  const Vec3 ns = glm::dot(s.ns, ng) >= 0.0f ? s.ns : -s.ns;
  return std::clamp(glm::dot(ns, s.wo), 0.0f, 1.0f);
}

// Multiscatter GGX glass (4.0+): Cycles keeps in the closure's weight the share E (1 + F_ms (1 -
// E) / E) of its energy compensation, with Fss the glass's transmission colour (sqrt of the base
// colour) and E, E_avg the glass's albedo as Cycles' tables give it and its cosine-weighted mean on
// this side (materials/dielectric_albedo.h). 1 for a white glass.
Vec3 glass_energy_share(const FresnelDielectric& glass, bool entering, float cos_o, const Vec3& fss) {
  if (glass.albedo < 0 || fss == Vec3(1.0f)) return Vec3(1.0f);
  const DielectricAlbedo& table = dielectric_albedo_table(glass.albedo);
  return multiscatter_glass_factor(table, entering, cos_o, fss) / multiscatter_glass_scale(table, entering, cos_o);
}

// 4.0+: Cycles' Principled closures from the top (kernel/svm/closure.h), each adding its weight
// times its estimated albedo and scaling the weight left for those below it.
Vec3 layered_principled_color(const Principled& m, const ShadingPoint& s, const Vec3& base_color) {
  const float cos_o = view_cosine(s);
  Vec3 sum(0.0f), weight(1.0f);
  if (m.coat > 0.0f) {
    // The coat closure's estimated albedo, taken off everything below (materials/coat.h).
    const CoatLayer coat = coat_layer(m.coat, m.coat_roughness, m.coat_eta, m.coat_f0, m.coat_tint, cos_o);
    sum += Vec3(coat.albedo);
    weight *= coat.below;
  }
  if (m.metallic > 0.0f) {
    sum += m.metallic * weight * lobe_weight_albedo(principled_metal_lobe(m, s, base_color), m.multiscatter);
    weight *= 1.0f - m.metallic;
  }
  if (m.transmission > 0.0f) {
    // The glass's reflection: a generalised Schlick from F0(IOR) x Specular Tint to 1, its
    // curve the IOR's, read from the table on either side (no smooth-surface case here).
    const Vec3 f0 = glm::clamp(Vec3(f0_from_ior(m.glass.ior)) * m.specular_tint, Vec3(0.0f), Vec3(1.0f));
    const Vec3 reflect = glm::mix(f0, Vec3(1.0f), ggx_fresnel_blend(m.roughness, cos_o, m.glass.ior));
    const bool entering = glm::dot(s.ng, s.wo) > 0.0f;
    const Vec3 fss = glm::sqrt(glm::clamp(base_color, Vec3(0.0f), Vec3(1.0f)));
    sum += m.transmission * weight * glass_energy_share(m.glass, entering, cos_o, fss) * reflect;
    weight *= 1.0f - m.transmission;
  }
  if (m.eta != 1.0f) sum += weight * lobe_weight_albedo(principled_specular_lobe(m, s), m.multiscatter);
  return sum;
}

// 3.x: the closures' weights (surface_shader_glossy sums them): the specular lobe's 1 - the
// glass's share, and the glass's reflection closure, its share times the Fresnel term at cos_o.
// (Cycles 3.x files its Multiscatter GGX glass under Transmission Color when Roughness > 0.05;
// TOYRT renders 3.x's glass single-scatter, with the reflection this counts: noted by the add-on.)
Vec3 principled_3x_color(const Principled& m, const ShadingPoint& s, const Vec3& base_color) {
  const float glass = (1.0f - m.metallic) * m.transmission;
  Vec3 sum(m.eta != 1.0f || m.metallic > 0.0f ? 1.0f - glass : 0.0f);
  if (glass > 0.0f) {
    FresnelDielectric g = m.glass;
    g.reflect_tint = Vec3(1.0f);
    sum += glass * glass_reflection_color(g, s);
  }
  (void)base_color;
  return sum;
}

}  // namespace

[[gnu::noinline]] Vec3 principled_pass_color(const Principled& m, const ShadingPoint& s, const Vec3& base_color) {
  return m.layered ? layered_principled_color(m, s, base_color) : principled_3x_color(m, s, base_color);
}

[[gnu::noinline]] Vec3 glass_pass_color(const Material& material, const ShadingPoint& s) {
  const FresnelDielectric* glass = std::get_if<FresnelDielectric>(&material);
  return glass ? glass_reflection_color(*glass, s) : Vec3(0.0f);
}

void add_layered_pass_color(const std::vector<Material>& materials, const std::vector<Texture>& textures,
                            FirstHit& hit) {
  if (!hit.found || hit.material < 0 || size_t(hit.material) >= materials.size()) return;
  const Material& material = materials[size_t(hit.material)];
  if (const Principled* p = std::get_if<Principled>(&material)) {
    // Its lobes are drawn one per sample (materials/principled.h); with a coat or a glass the
    // drawn one does not give Cycles' sum, so the pass takes the whole sum here.
    if (p->coat > 0.0f || p->transmission > 0.0f)
      hit.glossy = principled_pass_color(*p, hit.at, lambert_albedo(p->base, textures, hit.at.uv));
    return;
  }
  hit.glossy += glass_pass_color(material, hit.at);
}

Vec3 lobe_weight_albedo(const GlossyLobe& lobe, bool multiscatter) {
  const Vec3 albedo = lobe_albedo(lobe);
  return multiscatter ? albedo * ggx_albedo(std::sqrt(lobe.alpha), lobe.wo.z) : albedo;
}

}  // namespace toyrt
