// Emissive triangles as lights: every triangle of a mesh whose material emits (Blender's
// Emission shader, Principled Emission), placed by its instances in world space, with uniform
// radiance L = colour x strength on both sides (Cycles' mesh lights; a camera looking at an
// Emission surface of strength 1 and colour c sees c).
//
// Sampling: one triangle chosen with probability proportional to its power (area x mean
// radiance) from a CDF (binary search, so millions of triangles cost a log2 of them); then, close
// to it (its longest edge longer than the point's height over its plane, Cycles' rule), a
// direction uniform in its solid angle (lights/spherical_triangle.h: density P(triangle) / Omega),
// else a uniform point on it (density P(triangle) d^2 / (area |cos_light|)). A triangle
// whose material is not sampled as a light (Blender's emission sampling None) is left out: it
// is seen by rays that hit it, and lights nothing. Sides: Blender 4.x's emission sampling Front
// or Back samples only towards that side (Cycles' then lights nothing on the other side by NEE).
//
// The scene builds this at commit from its instances, meshes and materials (Scene::commit); a
// scene without emissive materials builds nothing and pays nothing.
#pragma once

#include "core/math.h"
#include "lights/light_sample.h"
#include "sampling/warp.h"

#include <cstdint>
#include <vector>

namespace toyrt {

enum class EmitterSides : uint8_t { Both = 3, Front = 1, Back = 2 };

struct EmissiveTriangle {
  Vec3 p0{0.0f}, e1{0.0f}, e2{0.0f};  // world space: p0, p1 - p0, p2 - p0
  Vec3 normal{0.0f};                  // unit, (e1 x e2) / |e1 x e2|: the front side
  Vec3 radiance{0.0f};
  float area = 0.0f;
  EmitterSides sides = EmitterSides::Both;
};

struct MeshEmitters {
  std::vector<EmissiveTriangle> triangles;  // of positive area and radiance only
  std::vector<float> cdf;                   // triangles.size() + 1 values from 0 to 1, by power
  double total_power = 0.0;                 // sum of area x mean radiance (W/sr, for importance)

  bool empty() const { return triangles.empty(); }
  // Keeps `t` if it has area and radiance (a zero-area triangle cannot emit anything).
  void add(const EmissiveTriangle& t);
  void finish();  // builds the CDF once every triangle is added
};

// A point on one emissive triangle seen from p (u: two uniform numbers, the first also choosing
// the triangle). No sample when the chosen triangle faces away on a side it does not emit to.
LightSample sample_emitters(const MeshEmitters& emitters, const Vec3& p, const Vec2& u);

// The solid-angle density sample_emitters() gives the direction wi from p when it meets emissive
// triangle t (world space, as gathered) at `distance`: P(t) = its power / the total, times its
// own density (1 / Omega close to it, d^2 / (area |cos|) further away); 0 where t's side facing p
// is not sampled. For multiple importance sampling against rays that hit emitters.
float emitter_pdf(const MeshEmitters& emitters, const Vec3& p, const EmissiveTriangle& t, const Vec3& wi,
                  float distance);

}  // namespace toyrt
