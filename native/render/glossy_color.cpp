#include "render/glossy_color.h"

#include "materials/fresnel.h"
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

[[gnu::noinline]] Vec3 glass_pass_color(const Material& material, const ShadingPoint& s) {
  const FresnelDielectric* glass = std::get_if<FresnelDielectric>(&material);
  if (!glass) return Vec3(0.0f);
  const FresnelDielectric& m = *glass;
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

void add_glass_pass_color(const std::vector<Material>& materials, FirstHit& hit) {
  if (hit.found && hit.material >= 0 && size_t(hit.material) < materials.size())
    hit.glossy += glass_pass_color(materials[size_t(hit.material)], hit.at);
}

Vec3 lobe_weight_albedo(const GlossyLobe& lobe, bool multiscatter) {
  const Vec3 albedo = lobe_albedo(lobe);
  return multiscatter ? albedo * ggx_albedo(std::sqrt(lobe.alpha), lobe.wo.z) : albedo;
}

}  // namespace toyrt
