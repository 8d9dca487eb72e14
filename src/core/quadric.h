// Quadrics, the base primitives of free-form surfaces, with interval bounds and projective maps —
// core maths, because the scene's loaders build quadrics and the free-form stage casts them.
//
// Based on: SPEC §11 (seed 003: quadrics F = Ax² + By² + Cz² + Dxy + Exz + Fyz + Gx + Hy + Iz + K),
// §12 (a quadric stays a quadric under a projective map, S' = M^{-T} S M^{-1}; a projective map of
// space is fixed by five point pairs, no four coplanar). Interval arithmetic as in libfive's
// recursive subdivision (Keeter 2020, "Massively Parallel Rendering of Complex Closed-Form Implicit
// Surfaces").
//
// Sign convention (SPEC §11 leaves it to the implementation): the surface is F = 0 and the
// inside is F ≥ 0 — a sphere of radius r about c is 1 − |p − c|²/r², which is 1 at its centre
// whatever its size, so a perturbation's weight sets its height the same way for any radius.
#pragma once

#include <algorithm>
#include <array>
#include <limits>
#include <optional>

#include "synthvis/math.h"

namespace sv {

// Vec4d and Mat4d are synthvis/math.h's Vec4 and Mat4 in double (Vec3d is math.h's own), for the free forms'
// arithmetic: a quadric carried into the cube by a projective map and its interval bounds lose
// the surface in float (the map's entries span many orders of magnitude near the far plane).
// Mat4d is row-major (m[r][c]), as SPEC §12 writes S' = M^{-T} S M^{-1} and a quadric's matrix;
// render turns the camera's column-major Mat4 into it (render/freeforms.cpp).
struct Vec4d {
  double v[4] = {0, 0, 0, 0};
  double& operator[](int i) { return v[i]; }
  double operator[](int i) const { return v[i]; }
};

// A 4×4 matrix in double, row-major: m[r][c]. Acts on column vectors.
struct Mat4d {
  std::array<std::array<double, 4>, 4> m{{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};
  friend Mat4d operator*(const Mat4d& a, const Mat4d& b);
  Vec4d operator*(const Vec4d& v) const;
  Mat4d transposed() const;
  // The inverse by Gauss–Jordan elimination with partial pivoting; nothing when singular (a pivot
  // below 1e-300 relative to the row scale).
  std::optional<Mat4d> inverse() const;
  // The point p (w = 1) mapped and divided by its w.
  Vec3d transformPoint(Vec3d p) const;
  // A (column-major, float) Mat4 in double.
  static Mat4d of(const Mat4& m) {
    Mat4d d;
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) d.m[size_t(r)][size_t(c)] = m.m[c][r];
    return d;
  }
};

// The projective map of space taking src[i] to dst[i] for i = 0…4 (SPEC §12: (C)(M^i) = r_i·(P^i),
// r_5 = 1), for affine points (w = 1). Nothing when four of either five are coplanar (no unique map
// exists). solveProjectiveMap (core/projective.h) with homogeneous points and the refusal's reason.
std::optional<Mat4d> projectiveFromFivePoints(const std::array<Vec3d, 5>& src,
                                              const std::array<Vec3d, 5>& dst);

// A closed interval [lo, hi] with conservative arithmetic (no directed rounding: bounds are widened
// by a relative ulp-scale margin where the surface test reads them, raycast.cpp).
struct Interval {
  double lo = 0, hi = 0;
  static Interval point(double v) { return {v, v}; }
  bool containsZero() const { return lo <= 0 && hi >= 0; }
  friend Interval operator+(Interval a, Interval b) { return {a.lo + b.lo, a.hi + b.hi}; }
  friend Interval operator+(Interval a, double b) { return {a.lo + b, a.hi + b}; }
  friend Interval operator*(Interval a, double s) {
    return s >= 0 ? Interval{a.lo * s, a.hi * s} : Interval{a.hi * s, a.lo * s};
  }
  friend Interval operator*(Interval a, Interval b) {
    const double p0 = a.lo * b.lo, p1 = a.lo * b.hi, p2 = a.hi * b.lo, p3 = a.hi * b.hi;
    return {std::min(std::min(p0, p1), std::min(p2, p3)),
            std::max(std::max(p0, p1), std::max(p2, p3))};
  }
};
// Exact: [0, …] when a contains 0.
inline Interval square(Interval a) {
  const double l = a.lo * a.lo, h = a.hi * a.hi;
  if (a.lo <= 0 && a.hi >= 0) return {0, std::max(l, h)};
  return {std::min(l, h), std::max(l, h)};
}
inline Interval cube(Interval a) { return {a.lo * a.lo * a.lo, a.hi * a.hi * a.hi}; }  // monotonic
inline Interval positivePart(Interval a) { return {std::max(a.lo, 0.0), std::max(a.hi, 0.0)}; }
// The exact range of a·t² + b·t + c over t ∈ T: its ends, and its vertex −b/2a when inside.
inline Interval quadraticRange(double a, double b, double c, Interval t) {
  auto f = [&](double v) { return (a * v + b) * v + c; };
  double lo = std::min(f(t.lo), f(t.hi)), hi = std::max(f(t.lo), f(t.hi));
  if (a != 0) {
    const double vertex = -b / (2 * a);
    if (vertex > t.lo && vertex < t.hi) {
      lo = std::min(lo, f(vertex));
      hi = std::max(hi, f(vertex));
    }
  }
  return {lo, hi};
}
// The same over b ∈ B and c ∈ C as well — exact when b and c are independent of t and of each
// other: for fixed t it is linear in b, so b's ends suffice.
inline Interval quadraticRange(double a, Interval b, Interval c, Interval t) {
  const Interval r0 = quadraticRange(a, b.lo, 0.0, t), r1 = quadraticRange(a, b.hi, 0.0, t);
  return {std::min(r0.lo, r1.lo) + c.lo, std::max(r0.hi, r1.hi) + c.hi};
}

// F(x, y, z) = Ax² + By² + Cz² + Dxy + Exz + Fyz + Gx + Hy + Iz + K: coefficients in this order.
struct Quadric {
  std::array<double, 10> c{};

  // Convenience forms, all inside ≥ 0. Axes need not be unit length (they are normalized).
  static Quadric sphere(Vec3d centre, double radius);  // 1 − |p − c|²/r²
  static Quadric ellipsoid(Vec3d centre, Vec3d radii);  // 1 − Σ ((p_i − c_i)/r_i)², axis-aligned
  // The infinite cylinder of `radius` about the line through `point` along `axis`:
  // 1 − (distance from the axis)²/r².
  static Quadric cylinder(Vec3d point, Vec3d axis, double radius);
  // The infinite double cone with apex `apex`, axis `axis`, half-angle `halfAngle` (radians):
  // ((p − a)·u)² − cos²θ·|p − a|².
  static Quadric cone(Vec3d apex, Vec3d axis, double halfAngle);
  // The paraboloid of revolution opening along `axis` from `vertex`: inside where the height along
  // the axis exceeds k·(distance from the axis)²: h − k·ρ².
  static Quadric paraboloid(Vec3d vertex, Vec3d axis, double k);
  // The half-space n·p ≤ d (inside), bounded by the plane n·p = d: (d − n·p)/|n|, the signed
  // distance.
  static Quadric halfSpace(Vec3d normal, double d);

  double evaluate(Vec3d p) const;
  Vec3d gradient(Vec3d p) const;
  // A range that contains F over the box x × y × z (interval arithmetic, the square terms exact).
  Interval bound(Interval x, Interval y, Interval z) const;

  // The symmetric matrix S with F(p) = (p, 1)ᵀ S (p, 1).
  Mat4d matrix() const;
  static Quadric fromMatrix(const Mat4d& s);  // reads the symmetric part
  // The quadric of the image of this one's points under the map `inverse`⁻¹: S' = M^{-T} S M^{-1}
  // with M^{-1} = `inverse` given. Then F'(q) = (u(q))²·F(p) for q the image of p, where u(q) is
  // the w of M^{-1}·(q, 1) — the same sign, so the same surface and inside.
  Quadric transformedByInverse(const Mat4d& inverse) const;
};

}  // namespace sv
