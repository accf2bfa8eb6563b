#include "materials/diffuse_glossy.h"

namespace toyrt {

DiffuseGlossy DiffuseGlossy::from_params(const Params& params) {
  DiffuseGlossy m;
  m.diffuse = Lambert::from_params(params);
  m.diffuse_weight = float(params.non_negative("diffuse_weight", m.diffuse_weight));
  const Glossy d;
  m.glossy = Glossy::make(params.color("glossy_color", d.color), float(params.number("roughness", d.roughness)),
                          shadowing_from_params(params));
  return m;
}

Scatter scatter(const DiffuseGlossy& m, const ShadingPoint& s, const MaterialContext& ctx) {
  Scatter sc = scatter(m.glossy, s, ctx);
  sc.f = m.diffuse_weight * lambert_f(lambert_albedo(m.diffuse, *ctx.textures, s.uv));
  return sc;
}

}  // namespace toyrt
