#include "render/dielectric_lighting.h"

#include "geometry/offset_ray.h"
#include "render/glossy_lighting.h"
#include "render/transparent_walk.h"
#include "sampling/sobol_owen.h"

#include <cmath>

namespace toyrt {

DielectricStep dielectric_vertex(const Scene& scene, const Vec3& p, const Vec3& ng, TriangleRef self,
                                 const DielectricLobe& lobe, uint32_t pixel, uint32_t sample, uint32_t light_dim,
                                 uint32_t lobe_dim, uint32_t side_dim, uint32_t emitter_dim,
                                 const IntegratorSettings& settings, uint8_t receiver_set) {
  DielectricStep step;
  const Vec3 above = offset_ray_origin(p, ng), below = offset_ray_origin(p, -ng);
  const LobeVertex lv{nullptr, &lobe, p, ng, above, below, self};
  step.radiance = lobe_vertex_lighting(scene, lv, pixel, sample, light_dim, emitter_dim, settings, receiver_set);
  const BsdfSample g = dielectric_sample(lobe, sobol_owen_2d(pixel, sample, lobe_dim, settings.seed),
                                         sobol_owen_1d(pixel, sample, side_dim, settings.seed));
  if (!(g.pdf > 0.0f)) return step;
  const float side = glm::dot(g.wi, ng), cos_i = glm::dot(lobe.frame.n, g.wi);
  if (side == 0.0f || (side > 0.0f) != (cos_i > 0.0f)) return step;  // the shading frame's side is wrong
  step.wi = g.wi;
  step.weight = g.weight;
  step.pdf = g.pdf;
  step.origin = side > 0.0f ? above : below;
  return step;
}

}  // namespace toyrt
