// The one interaction a material offers the integrator, with one signature for every type:
//     Scatter scatter(const X&, const ShadingPoint&, const MaterialContext&);
// The answer is either "diffuse with BRDF value f" (the integrator samples the lights there and
// ends the path: direct lighting, as Cycles with max bounces 0), a glossy lobe (lights sampled
// with MIS against the lobe, then the path continues along a direction the lobe draws:
// materials/glossy_lobe.h) or up to two specular branches, which the path follows. The
// integrator has no per-type code: it visits the Material variant with a generic lambda, so a
// type without scatter() fails to compile.
#pragma once

#include "core/math.h"
#include "materials/burley_diffuse.h"
#include "materials/dielectric_lobe.h"
#include "materials/glossy_lobe.h"
#include "materials/texture.h"
#include "sampling/sobol_owen.h"

#include <cstdint>
#include <vector>

namespace toyrt {

// The hit as a material sees it. Normals come as stored (either side of the surface): each
// material orients them (refraction.h says how the sides decide entering and leaving).
struct ShadingPoint {
  Vec3 wo{0.0f};  // unit, back along the incoming ray
  Vec3 ng{0.0f};  // unit geometric normal
  Vec3 ns{0.0f};  // unit shading (smooth) normal
  Vec2 uv{0.0f};
};

// What a material may read besides the hit: the scene's textures and the render's choices.
struct MaterialContext {
  const std::vector<Texture>* textures = nullptr;
  // Split a random choice (reflect or refract) into all its branches, each weighted by its
  // probability, instead of drawing one (IntegratorSettings::split_depth).
  bool split = false;
  // The one uniform number a material may draw at this vertex: a Sobol-Owen dimension fixed per
  // path vertex, computed only when asked for, so a diffuse hit pays for none.
  uint32_t pixel = 0, sample = 0, dimension = 0, seed = 0;
  float uniform() const { return sobol_owen_1d(pixel, sample, dimension, seed); }
  // Another, for a material that picks one of its lobes where the integrator also samples lights
  // (the lights' choice reads `dimension`: one number for both would correlate them).
  uint32_t lobe_dimension = 0;
  float lobe_uniform() const { return sobol_owen_1d(pixel, sample, lobe_dimension, seed); }
};

struct SpecularSample {
  Vec3 wi{0.0f};           // unit direction leaving the surface
  bool reflected = false;  // mirror direction (always, under total internal reflection)
  bool total_internal_reflection = false;
  bool entering = false;     // wo was on the geometric normal's side
  float probability = 1.0f;  // of this branch: 1, or F / 1 - F for FresnelDielectric
  Vec3 weight{1.0f};         // f / pdf: the material's colour on this branch's side
  // The geometric normal on the side wi leaves into: offset_ray_origin(p, offset_normal).
  Vec3 offset_normal{0.0f};
};

struct Scatter {
  enum class Kind : uint8_t {
    Diffuse,     // direct lighting with BRDF value f, then the path ends
    Specular,    // the path continues along branches[0], its throughput times the branch's weight
    Split,       // each of the `count` branches is traced on its own, weighted by its probability
    Glossy,      // lights sampled with MIS against `glossy`, then the path continues along its sample;
                 // a diffuse part f, if not 0, gets its direct light as a Diffuse answer does
    Dielectric,  // a rough dielectric: lights sampled on both sides with MIS against `dielectric`,
                 // then the path continues along its sample (reflected or transmitted)
    Mixture,     // Cycles' closures side by side, combined as Cycles combines them: the diffuse part f,
                 // `glossy` and `second_glossy`, each picked with probability closure_pick's
                 // (materials/closure_mixture.h)
  };
  Kind kind = Kind::Diffuse;
  Vec3 f{0.0f};  // Diffuse, and Glossy's diffuse part (0: none): for directions on wo's side
  // Diffuse and Glossy's diffuse part: f times burley_factor(retro, wi) per light direction
  // (Blender 3.x's Principled diffuse, materials/burley_diffuse.h) instead of f alone.
  bool burley = false;
  BurleyDiffuse retro;
  // Glossy with a diffuse part: Cycles' probability of continuing along the glossy closure
  // (its sample weight over both), which decides what the continuation's next vertex scatters:
  // the whole BSDF over the closures' mixed pdf (render/closure_pick.h). 0: the lobe's own value.
  float glossy_pick = 0.0f;
  // Mixture: a second glossy closure (3.x's Clearcoat) and each closure's pick probability, x the
  // diffuse part's, y `glossy`'s, z `second_glossy`'s (Cycles' sample weights over their sum).
  GlossyLobe second_glossy;
  Vec3 closure_pick{0.0f};
  int count = 0;
  SpecularSample branches[2];
  GlossyLobe glossy;
  DielectricLobe dielectric;

  static Scatter diffuse(const Vec3& f) {
    Scatter s;
    s.f = f;
    return s;
  }
  static Scatter glossy_lobe(const GlossyLobe& lobe) {
    Scatter s;
    s.kind = Kind::Glossy;
    s.glossy = lobe;
    return s;
  }
  static Scatter dielectric_lobe(const DielectricLobe& lobe) {
    Scatter s;
    s.kind = Kind::Dielectric;
    s.dielectric = lobe;
    return s;
  }
  static Scatter specular(const SpecularSample& branch) {
    Scatter s;
    s.kind = Kind::Specular;
    s.count = 1;
    s.branches[0] = branch;
    return s;
  }
};

}  // namespace toyrt
