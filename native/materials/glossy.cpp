#include "materials/glossy.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace toyrt {

Glossy Glossy::make(const Vec3& color, float roughness, GgxShadowing shadowing) {
  if (!std::isfinite(roughness)) throw std::invalid_argument("glossy: roughness must be finite");
  if (!is_finite(color) || glm::any(glm::lessThan(color, Vec3(0.0f))))
    throw std::invalid_argument("glossy: color must be finite and >= 0");
  return Glossy{color, std::clamp(roughness, 0.0f, 1.0f), shadowing};
}

GgxShadowing shadowing_from_params(const Params& params) {
  const std::string shadowing = params.text("shadowing", "separable");
  if (shadowing != "separable" && shadowing != "correlated")
    throw std::invalid_argument("glossy: shadowing must be 'separable' or 'correlated', not '" + shadowing + "'");
  return shadowing == "separable" ? GgxShadowing::Separable : GgxShadowing::HeightCorrelated;
}

Glossy Glossy::from_params(const Params& params) {
  const Glossy d;
  return make(params.color("color", d.color), float(params.number("roughness", d.roughness)),
              shadowing_from_params(params));
}

Scatter scatter(const Glossy& m, const ShadingPoint& s, const MaterialContext&) {
  // Normals to wo's side, as the integrator orients them for its light samples; where wo is below
  // the shading normal's tangent plane (silhouettes of smooth meshes) the lobe sits on ng.
  const Vec3 ng = glm::dot(s.ng, s.wo) > 0.0f ? s.ng : -s.ng;
  Vec3 ns = glm::dot(s.ns, ng) >= 0.0f ? s.ns : -s.ns;
  if (glm::dot(s.wo, ns) <= 1e-6f) ns = ng;
  GlossyLobe lobe;
  lobe.frame = Frame::from_normal(ns);
  lobe.wo = lobe.frame.to_local(s.wo);
  lobe.wo.z = std::max(lobe.wo.z, 1e-6f);
  lobe.tint = m.color;
  lobe.alpha = ggx_alpha(m.roughness);
  lobe.shadowing = m.shadowing;
  return Scatter::glossy_lobe(lobe);
}

}  // namespace toyrt
