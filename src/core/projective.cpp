// Based on: SPEC §12 (seed 003, the five-point projective map); Hartley & Zisserman, Multiple
// View Geometry, 2nd ed., §2.3 (a projective frame fixes a projectivity).
//
// Derivation, in N dimensions of homogeneous coordinates (N = 4 for space, 3 for the plane): let
// [M] be the matrix whose columns are M^1 … M^N and λ = [M]⁻¹·M^{N+1}, so that
// M^{N+1} = Σ λ_j M^j. A = [M]·diag(λ) takes e_j to λ_j·M^j and (1, …, 1) to M^{N+1}; likewise
// B = [P]·diag(μ) with μ = [P]⁻¹·P^{N+1}. Then C = B·A⁻¹ = [P]·diag(μ/λ)·[M]⁻¹ takes M^j to
// (μ_j/λ_j)·P^j (r_j = μ_j/λ_j) and M^{N+1} to B·(1, …, 1) = P^{N+1} (r_{N+1} = 1). A λ_j or μ_j
// of zero means the point left out together with the others is dependent — the same condition as
// a vanishing determinant of N of the N + 1 points, which is what is tested, on unit-length copies
// of the points so that the test does not depend on their scale.
#include "core/projective.h"

#include <fmt/format.h>

#include <cmath>
#include <string>

namespace sv {
namespace {

template <int N>
using Point = std::array<double, N>;

// The N×N block of a Mat4d (the rest identity), so that one Gauss–Jordan inverse (Mat4d::inverse)
// serves both dimensions: the inverse of [[A, 0], [0, I]] is [[A⁻¹, 0], [0, I]].
template <int N>
Mat4d embed(const std::array<Point<N>, N>& columns) {
  Mat4d a;
  for (int r = 0; r < N; ++r)
    for (int c = 0; c < N; ++c) a.m[size_t(r)][size_t(c)] = columns[size_t(c)][size_t(r)];
  return a;
}

// The determinant of the N×N matrix of `columns` (Laplace along the first row; N ≤ 4).
template <int N>
double determinant(const std::array<Point<N>, N>& columns) {
  if constexpr (N == 1) {
    return columns[0][0];
  } else {
    double det = 0, sign = 1;
    for (int skip = 0; skip < N; ++skip, sign = -sign) {
      std::array<Point<N - 1>, N - 1> minor{};
      for (int c = 0, k = 0; c < N; ++c) {
        if (c == skip) continue;
        for (int r = 1; r < N; ++r) minor[size_t(k)][size_t(r - 1)] = columns[size_t(c)][size_t(r)];
        ++k;
      }
      det += sign * columns[size_t(skip)][0] * determinant<N - 1>(minor);
    }
    return det;
  }
}

// "1, 2, 3 and 5": the numbers (from 1, as SPEC §12 counts) of the n + 1 points but `leftOut`.
std::string pointList(int n, int leftOut) {
  std::string s;
  for (int i = 0, listed = 0; i <= n; ++i) {
    if (i == leftOut) continue;
    if (listed > 0) s += listed == n - 1 ? " and " : ", ";
    s += std::to_string(i + 1);
    ++listed;
  }
  return s;
}

// Step 1 for one side: unit-length copies of the points, refused when zero, not finite, or when
// N of them are dependent. `side` ("source" or "target") and `dependent` ("coplanar",
// "collinear") name the problem.
template <int N>
Result<std::array<Point<N>, N + 1>> unitFrame(const std::array<Point<N>, N + 1>& p,
                                              const char* side, const char* dependent) {
  std::array<Point<N>, N + 1> u{};
  for (int i = 0; i <= N; ++i) {
    double len2 = 0;
    bool finite = true;
    for (double v : p[size_t(i)]) {
      finite = finite && std::isfinite(v);
      len2 += v * v;
    }
    if (!finite || !(len2 > 0) || !std::isfinite(len2))
      return Error{"", "",
                   fmt::format("{} point {} is {}: not a point", side, i + 1,
                               finite ? "zero" : "not finite")};
    const double inv = 1 / std::sqrt(len2);
    for (int k = 0; k < N; ++k) u[size_t(i)][size_t(k)] = p[size_t(i)][size_t(k)] * inv;
  }
  for (int leftOut = 0; leftOut <= N; ++leftOut) {
    std::array<Point<N>, N> cols{};
    for (int i = 0, k = 0; i <= N; ++i)
      if (i != leftOut) cols[size_t(k++)] = u[size_t(i)];
    const double independence = std::fabs(determinant<N>(cols));
    if (!(independence > kMinPointIndependence))
      return Error{
          "", "",
          fmt::format("{} points {} are {} (normalized determinant {:.3g}, at most {:g}): "
                      "no unique projective map fixes them",
                      side, pointList(N, leftOut), dependent, independence, kMinPointIndependence)};
  }
  return u;
}

// Steps 2–3: C = [P]·diag(μ/λ)·[M]⁻¹ on the unit copies, scaled back so that C·M^{N+1} is
// P^{N+1} itself (r_{N+1} = 1 holds for the caller's points, not only for the unit copies).
template <int N>
Result<std::array<Point<N>, N>> solveFrame(const std::array<Point<N>, N + 1>& M,
                                           const std::array<Point<N>, N + 1>& P,
                                           const char* dependent) {
  Result<std::array<Point<N>, N + 1>> m = unitFrame<N>(M, "source", dependent);
  if (!m.ok()) return m.error();
  Result<std::array<Point<N>, N + 1>> p = unitFrame<N>(P, "target", dependent);
  if (!p.ok()) return p.error();
  std::array<Point<N>, N> mCols{}, pCols{};
  for (int j = 0; j < N; ++j) {
    mCols[size_t(j)] = m.value()[size_t(j)];
    pCols[size_t(j)] = p.value()[size_t(j)];
  }
  // Independence above was checked, so these inverses exist unless the pivots are tiny relative
  // to Mat4d::inverse's own threshold — reported the same way.
  const std::optional<Mat4d> mInv = embed<N>(mCols).inverse(), pInv = embed<N>(pCols).inverse();
  if (!mInv || !pInv)
    return Error{"", "", fmt::format("the points are too nearly dependent to solve the map")};
  Point<N> lambda{}, mu{};
  for (int r = 0; r < N; ++r)
    for (int c = 0; c < N; ++c) {
      lambda[size_t(r)] += mInv->m[size_t(r)][size_t(c)] * m.value()[N][size_t(c)];
      mu[size_t(r)] += pInv->m[size_t(r)][size_t(c)] * p.value()[N][size_t(c)];
    }
  // The unit copies are M^i/|M^i|; the map C' found for them takes M^{N+1}/|M^{N+1}| to
  // P^{N+1}/|P^{N+1}|, so C = C'·|P^{N+1}|/|M^{N+1}|.
  double mLen = 0, pLen = 0;
  for (int k = 0; k < N; ++k) {
    mLen += M[N][size_t(k)] * M[N][size_t(k)];
    pLen += P[N][size_t(k)] * P[N][size_t(k)];
  }
  const double scale = std::sqrt(pLen) / std::sqrt(mLen);
  std::array<Point<N>, N> C{};  // C[r][c], row-major
  for (int r = 0; r < N; ++r)
    for (int c = 0; c < N; ++c) {
      double s = 0;
      for (int j = 0; j < N; ++j)
        s += pCols[size_t(j)][size_t(r)] * (mu[size_t(j)] / lambda[size_t(j)]) *
             mInv->m[size_t(j)][size_t(c)];
      C[size_t(r)][size_t(c)] = s * scale;
    }
  return C;
}

}  // namespace

Mat3d operator*(const Mat3d& a, const Mat3d& b) {
  Mat3d r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      r.m[size_t(i)][size_t(j)] = a.m[size_t(i)][0] * b.m[0][size_t(j)] +
                                  a.m[size_t(i)][1] * b.m[1][size_t(j)] +
                                  a.m[size_t(i)][2] * b.m[2][size_t(j)];
  return r;
}

std::optional<Mat3d> Mat3d::inverse() const {
  Mat4d a;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) a.m[size_t(r)][size_t(c)] = m[size_t(r)][size_t(c)];
  const std::optional<Mat4d> inv = a.inverse();
  if (!inv) return std::nullopt;
  Mat3d out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out.m[size_t(r)][size_t(c)] = inv->m[size_t(r)][size_t(c)];
  return out;
}

Result<Mat4d> solveProjectiveMap(const std::array<Vec4d, 5>& M, const std::array<Vec4d, 5>& P) {
  std::array<Point<4>, 5> m{}, p{};
  for (size_t i = 0; i < 5; ++i)
    for (int k = 0; k < 4; ++k) {
      m[i][size_t(k)] = M[i][k];
      p[i][size_t(k)] = P[i][k];
    }
  Result<std::array<Point<4>, 4>> c = solveFrame<4>(m, p, "coplanar");
  if (!c.ok()) return c.error();
  Mat4d out;
  for (size_t r = 0; r < 4; ++r) out.m[r] = c.value()[r];
  return out;
}

Result<Mat3d> solveHomography(const std::array<Vec3d, 4>& M, const std::array<Vec3d, 4>& P) {
  std::array<Point<3>, 4> m{}, p{};
  for (size_t i = 0; i < 4; ++i) {
    m[i] = {M[i].x, M[i].y, M[i].z};
    p[i] = {P[i].x, P[i].y, P[i].z};
  }
  Result<std::array<Point<3>, 3>> c = solveFrame<3>(m, p, "collinear");
  if (!c.ok()) return c.error();
  Mat3d out;
  for (size_t r = 0; r < 3; ++r) out.m[r] = c.value()[r];
  return out;
}

}  // namespace sv
