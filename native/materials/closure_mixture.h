// Several closures at one vertex, combined as Cycles combines them: Blender 3.x's Principled with
// Clearcoat (its diffuse, specular and clearcoat closures; Scatter::Kind::Mixture). Cycles
// evaluates every closure along a direction, sums their values and mixes their pdfs by the
// closures' sample weights; that mixed pdf weighs the light sample's and the BSDF sample's MIS,
// and the BSDF sample follows one closure picked by those weights. Where every closure reports
// the density it samples, any unbiased estimator converges to the same image. 3.x's clearcoat does
// not (materials/clearcoat.h: it reports the GTR1 pdf and samples GGX's visible normals), so the
// image depends on the estimator, and copying Cycles' is what matches it: the mixture converges to
//     integral of F cos L (p_light^2 + P_drawn P) / (p_light^2 + P^2)
// per direction (P the mixed reported pdf, P_drawn the mixture's real density), where TOYRT's own
// one-lobe draw would converge to the clearcoat's bias undiluted by the other closures.
#pragma once

#include "core/math.h"
#include "materials/scatter.h"
#include "sampling/warp.h"

namespace toyrt {

// f (all closures) and the mixed pdf along wi (world, unit); 0 below the shading normal. The
// caller checks that wi leaves on the geometric normal's side.
inline BsdfEval mixture_eval(const Scatter& sc, const Vec3& wi) {
  const float cos = glm::dot(sc.second_glossy.frame.n, wi);
  if (!(cos > 0.0f)) return {};
  BsdfEval e;
  if (sc.closure_pick.x > 0.0f) {
    e.f = sc.burley ? sc.f * burley_factor(sc.retro, wi) : sc.f;
    e.pdf = sc.closure_pick.x * cos * kInvPi;
  }
  if (sc.closure_pick.y > 0.0f) {
    const BsdfEval g = evaluate_lobe(sc.glossy, wi);
    e.f += g.f;
    e.pdf += sc.closure_pick.y * g.pdf;
  }
  if (sc.closure_pick.z > 0.0f) {
    const BsdfEval g = evaluate_lobe(sc.second_glossy, wi);
    e.f += g.f;
    e.pdf += sc.closure_pick.z * g.pdf;
  }
  return e;
}

// A direction from the closure `pick` (uniform in [0, 1)) chooses, drawn from u, with the whole
// mixture's f cos / pdf and pdf (0: none). diffuse: whether the diffuse closure drew it (Cycles'
// path then ends after the light the ray finds: diffuse bounces 0).
inline BsdfSample mixture_sample(const Scatter& sc, float pick, const Vec2& u, bool& diffuse) {
  diffuse = pick < sc.closure_pick.x;
  Vec3 wi;
  if (diffuse) {
    wi = sc.second_glossy.frame.to_world(sample_cosine_hemisphere(u));
  } else {
    const BsdfSample s = sample_lobe(pick < sc.closure_pick.x + sc.closure_pick.y ? sc.glossy : sc.second_glossy, u);
    if (!(s.pdf > 0.0f)) return {};
    wi = s.wi;
  }
  const BsdfEval e = mixture_eval(sc, wi);
  if (!(e.pdf > 0.0f)) return {};
  return {wi, e.f * (glm::dot(sc.second_glossy.frame.n, wi) / e.pdf), e.pdf};
}

}  // namespace toyrt
