// Emissive triangles as lights: every triangle of a mesh whose material emits (Blender's
// Emission shader, Principled Emission), placed by its instances in world space, with uniform
// radiance L = colour x strength on both sides (Cycles' mesh lights; a camera looking at an
// Emission surface of strength 1 and colour c sees c).
//
// Sampling: one triangle chosen with probability proportional to its power (area x mean
// radiance) from a CDF (binary search, so millions of triangles cost a log2 of them), or, from
// kEmitterTreeFrom triangles spread over the scene, by its expected contribution at the shading
// point (and its normal) through a
// light tree over them (lights/light_tree.h, the lamps' tree built from the triangles' bounds:
// near ones and ones facing the point are chosen more); then, close
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
#include "lights/light_bounds.h"
#include "lights/light_sample.h"
#include "lights/light_tree.h"
#include "sampling/warp.h"

#include <cstdint>
#include <vector>

namespace toyrt {

// Scenes with at least this many sampled emissive triangles, whose box spans at least
// kEmitterTreeSpread of the scene's diagonal, pick them through a light tree; the others by the
// power CDF. Measured in docs/lights.md ("Emissive triangles through the light tree",
// bench_emitters): small quads spread over a room's ceiling render with 3.6 to 5.8x less error at
// equal time through the tree from 18 to 2,048 triangles (0.94x at 8, 1.7 to 2.5x at 8k-33k); one
// compact emitter (a ball of 12 to 65,000 triangles over a floor) renders with 1.4 to 2.2x more
// error at equal time through it at every count: its CDF is near the best choice, and the tree's
// walk costs 10x the CDF's binary search. Hence a low count and a spread test: the share lies
// between the two measured cases (the ceiling spans 1.0 of its scene, the ball 0.06), above the
// parity scene "emitters" (a panel and a ball, 0.28), which rendered 3.9x slower through the tree
// (time against Cycles', same parity) at 1/4.
inline constexpr size_t kEmitterTreeFrom = 16;
inline constexpr float kEmitterTreeSpread = 0.5f;
// Triangles per leaf of their tree: measured in docs/lights.md. Unlike lamps (LightTree::kLeafSize
// 8), larger leaves gain no variance on triangles and cost a longer exact walk (8: 2.2x the time
// of a pick); 2 is as fast as 1 with half the nodes.
inline constexpr uint32_t kEmitterLeafSize = 2;

enum class EmitterSides : uint8_t { Both = 3, Front = 1, Back = 2 };

struct EmissiveTriangle {
  Vec3 p0{0.0f}, e1{0.0f}, e2{0.0f};  // world space: p0, p1 - p0, p2 - p0
  Vec3 normal{0.0f};                  // unit, (e1 x e2) / |e1 x e2|: the front side
  // Its uniform radiance; for a textured one (an image on the emission colour) an estimate of its
  // mean, which weighs it among the others: the scene evaluates the image where a sample lands
  // (EmitterPoint, Scene::emitted_at).
  Vec3 radiance{0.0f};
  float area = 0.0f;
  EmitterSides sides = EmitterSides::Both;
  bool textured = false;
};

// Where sample_emitters() landed: the triangle's index and, for a textured triangle, the point's
// barycentrics (b.x along e1, b.y along e2), for its emission.
struct EmitterPoint {
  size_t index = 0;
  Vec2 b{0.0f};
};

// What a light tree weighs a triangle by, as each lamp type provides (lights/light.h): its
// cluster importance as a node of one (the tree's own estimate), with its normal turned to p's
// side, and exactly zero on a side it does not emit to (where sample_emitters() finds nothing).
float importance(const EmissiveTriangle& t, const Vec3& p, const Vec3& n);
// Its box, power (area x mean radiance) and normal cone: one-sided (theta_o = 0 around the
// emitting side's normal) for emission sampling Front or Back, else any direction off its plane
// (Cycles' bounds: an axis in the plane, theta_o = pi / 2), theta_e = pi / 2 either way.
LightBounds bounds(const EmissiveTriangle& t);

struct MeshEmitters {
  std::vector<EmissiveTriangle> triangles;  // of positive area and radiance only
  // Per triangle, where hits find it (instance << 32 | triangle index), ascending (index_of()).
  std::vector<uint64_t> keys;
  std::vector<float> cdf;    // triangles.size() + 1 values from 0 to 1, by power (without the tree)
  double total_power = 0.0;  // sum of area x mean radiance (W/sr, for importance)
  LightTree tree;            // over the triangles from kEmitterTreeFrom of them, else empty

  bool empty() const { return triangles.empty(); }
  bool uses_tree() const { return tree.node_count() > 0; }
  // Keeps `t` if it has area and radiance (a zero-area triangle cannot emit anything). `key`:
  // where the scene's hits find it, added in ascending order (default: its position).
  void add(const EmissiveTriangle& t, uint64_t key = UINT64_MAX);
  // Builds the CDF once every triangle is added, or the tree from `tree_from` triangles on when
  // their box's diagonal is at least `min_diagonal` (the scene's x kEmitterTreeSpread; 0: always).
  void finish(size_t tree_from = kEmitterTreeFrom, uint32_t leaf_size = kEmitterLeafSize, float min_diagonal = 0.0f);
  // The triangle added with `key` (instance << 32 | triangle), or -1: not sampled as a light.
  int64_t index_of(uint64_t key) const;
  size_t memory_bytes() const;
};

// A point on one emissive triangle seen from p with normal n (n = 0: no receiver cosine; the tree
// weighs by it) (u: two uniform numbers, the first also choosing the triangle). No sample when
// the chosen triangle faces away on a side it does not emit to.
// `where` (optional) receives the triangle and point of a valid sample.
LightSample sample_emitters(const MeshEmitters& emitters, const Vec3& p, const Vec3& n, const Vec2& u,
                            EmitterPoint* where = nullptr);

// The probability that sample_emitters() chooses triangle `index` at (p, n): its power / the
// total, or the tree's probability (the same floats select() returned).
float emitter_probability(const MeshEmitters& emitters, const Vec3& p, const Vec3& n, size_t index);

// The solid-angle density sample_emitters() gives the direction wi from (p, n) when it meets
// emissive triangle `index` at `distance`: emitter_probability() times its own density (1 / Omega
// close to it, d^2 / (area |cos|) further away); 0 where its side facing p is not sampled. For
// multiple importance sampling against rays that hit emitters.
float emitter_pdf(const MeshEmitters& emitters, const Vec3& p, const Vec3& n, size_t index, const Vec3& wi,
                  float distance);

}  // namespace toyrt
