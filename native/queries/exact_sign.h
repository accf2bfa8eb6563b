// Exact signs of small polynomials in double-precision inputs, for the queries' topological
// decisions (which side of an edge a ray passes, whether a point lies on a plane). Each sign is
// first taken from the plain double evaluation when it clears a forward error bound (almost
// always); otherwise the polynomial is rebuilt as a sum of exactly representable terms
// (error-free products by fused multiply-add) and summed without error into a nonoverlapping
// expansion whose largest component has the sign of the true value (Shewchuk 1997, "Adaptive
// Precision Floating-Point Arithmetic and Fast Robust Geometric Predicates", Theorems 10 and 13).
// Exact as long as no partial product underflows (inputs of magnitude above about 1e-70), which
// float geometry always satisfies.
#pragma once

#include "core/math.h"

#include <cmath>

namespace toyrt::queries {

// a + b = s + e exactly (Knuth's two-sum: no precondition on the magnitudes).
inline void two_sum(double a, double b, double& s, double& e) {
  s = a + b;
  const double bv = s - a, av = s - bv;
  e = (a - av) + (b - bv);
}

// a * b = p + e exactly (the fused multiply-add rounds only once).
inline void two_product(double a, double b, double& p, double& e) {
  p = a * b;
  e = std::fma(a, b, -p);
}

// A sum of up to Capacity doubles kept exactly: components nonoverlapping, increasing in
// magnitude, zeros dropped. Fixed storage, so the slow path allocates nothing.
template <int Capacity>
struct Expansion {
  double c[Capacity];
  int n = 0;

  // Shewchuk's GROW-EXPANSION with zero elimination. The caller adds at most Capacity terms in
  // total: each call grows the expansion by at most one component.
  void add(double b) {
    int m = 0;
    double q = b;
    for (int i = 0; i < n; ++i) {
      double s, e;
      two_sum(q, c[i], s, e);
      q = s;
      if (e != 0.0) c[m++] = e;
    }
    if (q != 0.0) c[m++] = q;
    n = m;
  }
  // a * b, exactly.
  void add_product(double a, double b) {
    double p, e;
    two_product(a, b, p, e);
    add(p);
    add(e);
  }
  // a * b * c, exactly: the two parts of a * b each times c.
  void add_product(double a, double b, double c3) {
    double p, e;
    two_product(a, b, p, e);
    add_product(p, c3);
    add_product(e, c3);
  }
  int sign() const { return n == 0 ? 0 : (c[n - 1] > 0.0 ? 1 : -1); }
};

inline int sign_of(double x) { return (x > 0.0) - (x < 0.0); }

// Relative forward error bound of the double evaluations below, with margin: a triple product
// X . (Y x Z) evaluated naively errs by at most 7u (u = 2^-53) times its permanent (the same sum
// of absolute terms), Shewchuk's orient3d bound; 1e-15 is about 9u.
inline constexpr double kTripleErrorBound = 1e-15;

// sign(x . (y x z)) by exact expansion arithmetic: the slow path, kept out of line.
[[gnu::noinline, gnu::cold]] inline int triple_sign_exact(const DVec3& x, const DVec3& y, const DVec3& z) {
  Expansion<24> sum;
  sum.add_product(y.y, z.z, x.x);
  sum.add_product(-y.z, z.y, x.x);
  sum.add_product(y.z, z.x, x.y);
  sum.add_product(-y.x, z.z, x.y);
  sum.add_product(y.x, z.y, x.z);
  sum.add_product(-y.y, z.x, x.z);
  return sum.sign();
}

// x . (y x z) in double, and its sign when the error bound certifies it (else 2: undecided).
inline int triple_filtered(const DVec3& x, const DVec3& y, const DVec3& z, double& value) {
  const double a = y.y * z.z, b = y.z * z.y, c = y.z * z.x, d = y.x * z.z, e = y.x * z.y, f = y.y * z.x;
  value = x.x * (a - b) + x.y * (c - d) + x.z * (e - f);
  const double permanent = std::fabs(x.x) * (std::fabs(a) + std::fabs(b)) +
                           std::fabs(x.y) * (std::fabs(c) + std::fabs(d)) +
                           std::fabs(x.z) * (std::fabs(e) + std::fabs(f));
  return std::fabs(value) > kTripleErrorBound * permanent ? sign_of(value) : 2;
}

// sign(x . (y x z)) exactly.
inline int triple_sign(const DVec3& x, const DVec3& y, const DVec3& z) {
  double value;
  const int s = triple_filtered(x, y, z, value);
  return s != 2 ? s : triple_sign_exact(x, y, z);
}

// sign(a0 * b0 - a1 * b1 + a2 * b2 - a3 * b3) exactly: a 2x2 determinant of differences written
// out so that no difference is rounded.
[[gnu::noinline]] inline int four_product_sign(double a0, double b0, double a1, double b1, double a2, double b2,
                                               double a3, double b3) {
  Expansion<8> sum;
  sum.add_product(a0, b0);
  sum.add_product(-a1, b1);
  sum.add_product(a2, b2);
  sum.add_product(-a3, b3);
  return sum.sign();
}

// sign(x0 * y1 - x1 * y0) exactly (a 2D orientation about the origin).
inline int cross2_sign(double x0, double y0, double x1, double y1) {
  const double p = x0 * y1, q = x1 * y0;
  const double value = p - q;
  // Two rounded products and a rounded difference: 3u of the permanent, with margin.
  if (std::fabs(value) > 1e-15 * (std::fabs(p) + std::fabs(q))) return sign_of(value);
  Expansion<4> sum;
  sum.add_product(x0, y1);
  sum.add_product(-x1, y0);
  return sum.sign();
}

}  // namespace toyrt::queries
