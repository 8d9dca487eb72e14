// Based on: SPEC §11–§12 (seed 003). Quadric forms as sums of squared linear forms, the projective
// transform of a quadric's matrix, the five-point projective map, interval bounds.
#include "core/quadric.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/projective.h"

namespace sv {

Mat4d operator*(const Mat4d& a, const Mat4d& b) {
  Mat4d r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a.m[i][k] * b.m[k][j];
      r.m[i][j] = s;
    }
  return r;
}

Vec4d Mat4d::operator*(const Vec4d& v) const {
  Vec4d r;
  for (int i = 0; i < 4; ++i)
    r[i] = m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2] + m[i][3] * v[3];
  return r;
}

Mat4d Mat4d::transposed() const {
  Mat4d r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r.m[i][j] = m[j][i];
  return r;
}

std::optional<Mat4d> Mat4d::inverse() const {
  // Step 1: [M | I], each row scaled by its largest entry's magnitude for the pivot test.
  double a[4][8];
  double scale = 0;
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      a[i][j] = m[i][j];
      a[i][4 + j] = i == j ? 1 : 0;
      scale = std::max(scale, std::fabs(m[i][j]));
    }
  }
  if (!(scale > 0) || !std::isfinite(scale)) return std::nullopt;
  // Step 2: eliminate column by column with the largest pivot.
  for (int col = 0; col < 4; ++col) {
    int pivot = col;
    for (int r = col + 1; r < 4; ++r)
      if (std::fabs(a[r][col]) > std::fabs(a[pivot][col])) pivot = r;
    if (!(std::fabs(a[pivot][col]) > 1e-12 * scale)) return std::nullopt;
    if (pivot != col)
      for (int j = 0; j < 8; ++j) std::swap(a[pivot][j], a[col][j]);
    const double inv = 1 / a[col][col];
    for (int j = 0; j < 8; ++j) a[col][j] *= inv;
    for (int r = 0; r < 4; ++r) {
      if (r == col || a[r][col] == 0) continue;
      const double f = a[r][col];
      for (int j = 0; j < 8; ++j) a[r][j] -= f * a[col][j];
    }
  }
  Mat4d r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r.m[i][j] = a[i][4 + j];
  return r;
}

Vec3d Mat4d::transformPoint(Vec3d p) const {
  const Vec4d q = *this * Vec4d{{p.x, p.y, p.z, 1}};
  return {q[0] / q[3], q[1] / q[3], q[2] / q[3]};
}

namespace {

// S += w·v·vᵀ: quadric forms are sums of squared linear forms v·(p, 1).
void addSquare(Mat4d& s, const double v[4], double w) {
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) s.m[i][j] += w * v[i] * v[j];
}

Mat4d zeroMatrix() {
  Mat4d s;
  for (auto& row : s.m) row.fill(0);
  return s;
}

// −|p − a|² as squares of the forms (e_i, −a_i).
void addMinusDistanceSquared(Mat4d& s, Vec3d a, double w) {
  const double ax[3] = {a.x, a.y, a.z};
  for (int i = 0; i < 3; ++i) {
    double v[4] = {0, 0, 0, -ax[i]};
    v[i] = 1;
    addSquare(s, v, -w);
  }
}

// The linear form (p − a)·u as a 4-vector.
void axisForm(Vec3d a, Vec3d u, double v[4]) {
  v[0] = u.x;
  v[1] = u.y;
  v[2] = u.z;
  v[3] = -dot(u, a);
}

}  // namespace

std::optional<Mat4d> projectiveFromFivePoints(const std::array<Vec3d, 5>& src,
                                              const std::array<Vec3d, 5>& dst) {
  std::array<Vec4d, 5> m, p;
  for (size_t i = 0; i < 5; ++i) {
    m[i] = Vec4d{{src[i].x, src[i].y, src[i].z, 1}};
    p[i] = Vec4d{{dst[i].x, dst[i].y, dst[i].z, 1}};
  }
  Result<Mat4d> c = solveProjectiveMap(m, p);
  if (!c.ok()) return std::nullopt;
  return c.value();
}

Quadric Quadric::sphere(Vec3d centre, double radius) {
  return ellipsoid(centre, {radius, radius, radius});
}

Quadric Quadric::ellipsoid(Vec3d centre, Vec3d radii) {
  // 1 − Σ ((p_i − c_i)/r_i)²
  Mat4d s = zeroMatrix();
  s.m[3][3] = 1;
  const double c[3] = {centre.x, centre.y, centre.z}, r[3] = {radii.x, radii.y, radii.z};
  for (int i = 0; i < 3; ++i) {
    double v[4] = {0, 0, 0, -c[i] / r[i]};
    v[i] = 1 / r[i];
    addSquare(s, v, -1);
  }
  return fromMatrix(s);
}

Quadric Quadric::cylinder(Vec3d point, Vec3d axis, double radius) {
  // 1 − (|p − a|² − ((p − a)·u)²)/r²: the squared distance from the axis, over r².
  const Vec3d u = normalize(axis);
  const double w = 1 / (radius * radius);
  Mat4d s = zeroMatrix();
  s.m[3][3] = 1;
  addMinusDistanceSquared(s, point, w);
  double v[4];
  axisForm(point, u, v);
  addSquare(s, v, w);
  return fromMatrix(s);
}

Quadric Quadric::cone(Vec3d apex, Vec3d axis, double halfAngle) {
  // ((p − a)·u)² − cos²θ·|p − a|²: inside where the angle to the axis is below θ (both nappes).
  const Vec3d u = normalize(axis);
  const double c = std::cos(halfAngle);
  Mat4d s = zeroMatrix();
  addMinusDistanceSquared(s, apex, c * c);
  double v[4];
  axisForm(apex, u, v);
  addSquare(s, v, 1);
  return fromMatrix(s);
}

Quadric Quadric::paraboloid(Vec3d vertex, Vec3d axis, double k) {
  // h − k·ρ², h = (p − a)·u, ρ² = |p − a|² − h².
  const Vec3d u = normalize(axis);
  Mat4d s = zeroMatrix();
  addMinusDistanceSquared(s, vertex, k);
  double v[4];
  axisForm(vertex, u, v);
  addSquare(s, v, k);
  // + h: the linear part, split symmetrically between row and column 3.
  for (int i = 0; i < 4; ++i) {
    s.m[i][3] += 0.5 * v[i];
    s.m[3][i] += 0.5 * v[i];
  }
  return fromMatrix(s);
}

Quadric Quadric::halfSpace(Vec3d normal, double d) {
  // d − n·p with n normalized (and d with it), so that |F| is the distance to the plane.
  const double l = std::sqrt(dot(normal, normal));
  Quadric q;
  q.c[6] = -normal.x / l;
  q.c[7] = -normal.y / l;
  q.c[8] = -normal.z / l;
  q.c[9] = d / l;
  return q;
}

double Quadric::evaluate(Vec3d p) const {
  const double x = p.x, y = p.y, z = p.z;
  return c[0] * x * x + c[1] * y * y + c[2] * z * z + c[3] * x * y + c[4] * x * z + c[5] * y * z +
         c[6] * x + c[7] * y + c[8] * z + c[9];
}

Vec3d Quadric::gradient(Vec3d p) const {
  const double x = p.x, y = p.y, z = p.z;
  return {2 * c[0] * x + c[3] * y + c[4] * z + c[6], 2 * c[1] * y + c[3] * x + c[5] * z + c[7],
          2 * c[2] * z + c[4] * x + c[5] * y + c[8]};
}

Interval Quadric::bound(Interval x, Interval y, Interval z) const {
  // Exact in z, centred in x and y. With (x, y) = (x_c + h_x, y_c + h_y), |h| ≤ r:
  //   F = F(x_c, y_c, z) + F_x(x_c, y_c, z)·h_x + F_y(x_c, y_c, z)·h_y
  //       + A·h_x² + B·h_y² + D·h_x·h_y
  // exactly. The first term is a quadratic in z alone, bounded exactly (quadraticRange); the
  // gradient terms are linear in z, so their largest magnitudes over z are at its ends; the
  // remainder is second order in the window's size. Term-by-term interval arithmetic loses the
  // cancellation between terms that share x and y — in the cube, where coefficients are large
  // and nearly cancel, its excess was larger than the values themselves on small windows (seen on
  // BENCH.md's freeform: 4-pixel windows three object radii away from a surface kept).
  const double xc = 0.5 * (x.lo + x.hi), yc = 0.5 * (y.lo + y.hi);
  const double rx = 0.5 * (x.hi - x.lo), ry = 0.5 * (y.hi - y.lo);
  // F(x_c, y_c, z) = C·z² + (E·x_c + F·y_c + I)·z
  //                  + [A·x_c² + B·y_c² + D·x_c·y_c + G·x_c + H·y_c + K]
  const double b = c[4] * xc + c[5] * yc + c[8];
  const double k = (c[0] * xc + c[3] * yc + c[6]) * xc + (c[1] * yc + c[7]) * yc + c[9];
  const Interval centre = quadraticRange(c[2], b, k, z);
  // F_x = 2A·x_c + D·y_c + G + E·z, F_y = 2B·y_c + D·x_c + H + F·z.
  const double gx0 = 2 * c[0] * xc + c[3] * yc + c[6], gy0 = 2 * c[1] * yc + c[3] * xc + c[7];
  const double gx = std::max(std::fabs(gx0 + c[4] * z.lo), std::fabs(gx0 + c[4] * z.hi));
  const double gy = std::max(std::fabs(gy0 + c[5] * z.lo), std::fabs(gy0 + c[5] * z.hi));
  const double linear = gx * rx + gy * ry;
  // A·h_x² + B·h_y² + D·h_x·h_y over the box.
  const Interval quadratic = Interval{0, rx * rx} * c[0] + Interval{0, ry * ry} * c[1] +
                             Interval{-1, 1} * (std::fabs(c[3]) * rx * ry);
  return {centre.lo - linear + quadratic.lo, centre.hi + linear + quadratic.hi};
}

Mat4d Quadric::matrix() const {
  Mat4d s;
  s.m = {{{c[0], c[3] / 2, c[4] / 2, c[6] / 2},
          {c[3] / 2, c[1], c[5] / 2, c[7] / 2},
          {c[4] / 2, c[5] / 2, c[2], c[8] / 2},
          {c[6] / 2, c[7] / 2, c[8] / 2, c[9]}}};
  return s;
}

Quadric Quadric::fromMatrix(const Mat4d& s) {
  Quadric q;
  const auto& m = s.m;
  q.c = {
      m[0][0],           m[1][1],           m[2][2],           m[0][1] + m[1][0], m[0][2] + m[2][0],
      m[1][2] + m[2][1], m[0][3] + m[3][0], m[1][3] + m[3][1], m[2][3] + m[3][2], m[3][3]};
  return q;
}

Quadric Quadric::transformedByInverse(const Mat4d& inverse) const {
  return fromMatrix(inverse.transposed() * matrix() * inverse);
}

}  // namespace sv
