// The point of a triangle nearest to a point, in double precision: the Voronoi regions of the
// triangle's vertices, edges and face are told apart by the signs of dot products, as in
// Ericson's "Real-Time Collision Detection" (2005, section 5.1.5), so no projection onto a plane
// and no clamping of barycentrics is needed, and a degenerate triangle still gets an answer on
// its edges.
#pragma once

#include "core/math.h"

namespace toyrt::queries {

struct TriangleClosest {
  DVec3 point;
  double u, v;  // point = (1 - u - v) a + u b + v c
};

inline TriangleClosest closest_on_triangle(const DVec3& p, const DVec3& a, const DVec3& b, const DVec3& c) {
  const DVec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return {a, 0.0, 0.0};  // vertex a's region
  const DVec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return {b, 1.0, 0.0};  // vertex b's region
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {  // edge ab
    const double s = d1 / (d1 - d3);
    return {a + s * ab, s, 0.0};
  }
  const DVec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return {c, 0.0, 1.0};  // vertex c's region
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {  // edge ac
    const double s = d2 / (d2 - d6);
    return {a + s * ac, 0.0, s};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {  // edge bc
    const double s = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {b + s * (c - b), 1.0 - s, s};
  }
  // The face: barycentrics from the three sub-areas.
  const double inv = 1.0 / (va + vb + vc);
  const double u = vb * inv, v = vc * inv;
  return {a + u * ab + v * ac, u, v};
}

}  // namespace toyrt::queries
