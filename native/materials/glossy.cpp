#include "materials/glossy.h"

#include "materials/multiscatter.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace toyrt {

Glossy Glossy::make(const Vec3& color, float roughness, GgxShadowing shadowing, bool multiscatter,
                    MicrofacetDistribution distribution) {
  if (!std::isfinite(roughness)) throw std::invalid_argument("glossy: roughness must be finite");
  if (!is_finite(color) || glm::any(glm::lessThan(color, Vec3(0.0f))))
    throw std::invalid_argument("glossy: color must be finite and >= 0");
  if (multiscatter && distribution != MicrofacetDistribution::Ggx)
    throw std::invalid_argument("glossy: multiscatter is GGX's (Cycles has no Multiscatter Beckmann)");
  return Glossy{color, std::clamp(roughness, 0.0f, 1.0f), shadowing, multiscatter, distribution};
}

GgxShadowing shadowing_from_params(const Params& params) {
  const std::string shadowing = params.text("shadowing", "separable");
  if (shadowing != "separable" && shadowing != "correlated")
    throw std::invalid_argument("glossy: shadowing must be 'separable' or 'correlated', not '" + shadowing + "'");
  return shadowing == "separable" ? GgxShadowing::Separable : GgxShadowing::HeightCorrelated;
}

Glossy Glossy::from_params(const Params& params) {
  const Glossy d;
  const std::string distribution = params.text("distribution", "ggx");
  if (distribution != "ggx" && distribution != "beckmann")
    throw std::invalid_argument("glossy: distribution must be 'ggx' or 'beckmann', not '" + distribution + "'");
  return make(params.color("color", d.color), float(params.number("roughness", d.roughness)),
              shadowing_from_params(params), params.flag("multiscatter", d.multiscatter),
              distribution == "ggx" ? MicrofacetDistribution::Ggx : MicrofacetDistribution::Beckmann);
}

GlossyLobe oriented_lobe(const ShadingPoint& s, float roughness, GgxShadowing shadowing) {
  const Vec3 ng = glm::dot(s.ng, s.wo) > 0.0f ? s.ng : -s.ng;
  Vec3 ns = glm::dot(s.ns, ng) >= 0.0f ? s.ns : -s.ns;
  if (glm::dot(s.wo, ns) <= 1e-6f) ns = ng;
  GlossyLobe lobe;
  lobe.frame = Frame::from_normal(ns);
  lobe.wo = lobe.frame.to_local(s.wo);
  lobe.wo.z = std::max(lobe.wo.z, 1e-6f);
  lobe.alpha = ggx_alpha(roughness);
  lobe.shadowing = shadowing;
  return lobe;
}

Scatter scatter(const Glossy& m, const ShadingPoint& s, const MaterialContext&) {
  GlossyLobe lobe = oriented_lobe(s, m.roughness, m.shadowing);
  lobe.distribution = m.distribution;
  // Cycles' Glossy BSDF has its colour in the closure's weight and takes it as the lobe's average
  // Fresnel for the energy compensation.
  lobe.tint = m.multiscatter ? m.color * multiscatter_scale(m.roughness, lobe.wo.z, m.color) : m.color;
  return Scatter::glossy_lobe(lobe);
}

}  // namespace toyrt
