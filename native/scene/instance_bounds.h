// How far the ray an instance's walk follows can stray from the world ray, and the world box
// that stays conservative for it.
//
// A ray reaches an instance's mesh through to_object, in float: o' = to_object(o) and d' =
// to_object's linear part times d, each rounded, with a stored to_object that is to_world's
// inverse only up to its own rounding. The top level culls instances with world boxes made by
// sending the mesh box through to_world. For the two to agree (the walk never drops an instance
// whose object-space ray crosses its mesh), the world box must cover every world point x(t) =
// o + t d whose object-space counterpart o' + t d' lies in the mesh box. With A, a = to_world's
// linear part and translation, B, b = to_object's, F = A B - I and g = A b + a, that distance is
// at most
//     dev <= (f + k) (M + dev) + c + 3 k |o|
// (infinity norms: f = |F|, k = gamma(8) ||A| |B||, M the world box's largest coordinate,
// c = |g| + gamma(8) (||A| |b|| + |A| m) with m the mesh box's largest coordinate; the gamma
// terms are the rounding of the ray's transform and of the watertight test's translation by o').
// With f + k <= 1/4, dev <= 2 ((f + k) M + c) + 4 k |o| (the first term with room to spare, for
// the rounding of the box's own corners and of lo - pad; the second has its room in gamma(8),
// where the ray's transform and the test's translation round by about 13 units of 2^-24, which
// also covers o + pad rounded to nearest in make_ray_box_data): a pad per instance, applied to its box,
// plus a pad per ray that grows with the origin's distance, applied by the top-level walk
// (make_ray_box_data's pad). A transform with f + k > 1/4 has no float inverse worth the name
// (its rows nearly dependent): add_instance refuses it.
#pragma once

#include "core/bbox.h"

namespace toyrt {

struct TransformError {
  double inverse = 0.0;  // f = |to_world to_object - I|: how far the stored inverse is from one
  double spread = 0.0;   // k: the ray transform's rounding per unit of origin distance
  double offset = 0.0;   // c without the mesh-box term: |g| + gamma(8) ||A| |b||
  double reach = 0.0;    // gamma(8) |A|: times the mesh box's largest coordinate, part of c
  // Whether rays can be carried into object space with a bounded error (f + k <= 1/4).
  bool invertible() const { return inverse + spread <= 0.25; }
};

TransformError transform_error(const Mat4& to_world, const Mat4& to_object);

// The mesh box's corners through to_world, widened by their rounding and by the pad above.
BBox instance_world_bounds(const BBox& mesh_bounds, const Mat4& to_world, const TransformError& error);

// The per-ray pad's factor, 4 k rounded up to float: the top-level walk widens every box by this
// times the ray origin's largest coordinate (Scene::trace_instances).
float origin_pad_factor(const TransformError& error);

}  // namespace toyrt
