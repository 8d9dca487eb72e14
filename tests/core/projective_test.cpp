// The five-point projective map of SPEC §12 and the four-point homography: the maps reproduce
// their points, recover known maps (a perspective projection, random well-conditioned ones) from
// point pairs, and refuse dependent sets with the reason.
#include "core/projective.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace sv {
namespace {

double norm(const Vec4d& v) {
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]);
}
double norm(Vec3d v) { return std::sqrt(dot(v, v)); }

// Largest |C − R| over the entries, relative to R's largest entry.
// (Mat4d or Mat3d.)
template <class Matrix>
double relativeDifference(const Matrix& c, const Matrix& r) {
  double diff = 0, scale = 0;
  for (size_t i = 0; i < r.m.size(); ++i)
    for (size_t j = 0; j < r.m.size(); ++j) {
      diff = std::max(diff, std::fabs(c.m[i][j] - r.m[i][j]));
      scale = std::max(scale, std::fabs(r.m[i][j]));
    }
  return diff / scale;
}

// The identity plus normal noise of deviation `sigma` in every entry (Mat4d or Mat3d).
template <class Matrix>
Matrix perturbedIdentity(std::mt19937& rng, double sigma) {
  std::normal_distribution<double> g(0, sigma);
  Matrix a;
  for (auto& row : a.m)
    for (double& v : row) v += g(rng);
  return a;
}

// Five random points in general position, away from dependence: a projective frame (the unit
// points and their sum, homogeneous) each moved by up to `jitter` in every coordinate — so that the
// reproduction error measures the solver, not a nearly singular set (whose error grows with its
// condition number, as any solver's does).
std::array<Vec4d, 5> randomFrame(std::mt19937& rng, double jitter) {
  std::uniform_real_distribution<double> u(-jitter, jitter);
  std::array<Vec4d, 5> p = {Vec4d{{1, 0, 0, 0}}, Vec4d{{0, 1, 0, 0}}, Vec4d{{0, 0, 1, 0}},
                            Vec4d{{0, 0, 0, 1}}, Vec4d{{1, 1, 1, 1}}};
  for (auto& v : p)
    for (int k = 0; k < 4; ++k) v[k] += u(rng);
  return p;
}

// |C·M − r·P| / |C·M| for the r that fits best, and r itself: C·M^i must be a multiple of P^i.
double parallelError(const Vec4d& q, const Vec4d& p, double* r = nullptr) {
  double qp = 0, pp = 0;
  for (int k = 0; k < 4; ++k) qp += q[k] * p[k], pp += p[k] * p[k];
  const double s = qp / pp;
  if (r) *r = s;
  double e = 0;
  for (int k = 0; k < 4; ++k) e += (q[k] - s * p[k]) * (q[k] - s * p[k]);
  return std::sqrt(e) / norm(q);
}

TEST(FivePointMap, ReproducesItsFivePairsWithR5EqualToOne) {
  std::mt19937 rng(34);
  double worst = 0;
  for (int trial = 0; trial < 200; ++trial) {
    std::array<Vec4d, 5> M = randomFrame(rng, 0.25), P = randomFrame(rng, 0.25);
    if (trial == 0) M[2] = Vec4d{{0.25, 0.5, 1, 0}};  // a point at infinity is a point
    // Arbitrary homogeneous scales change nothing but r_i.
    for (size_t i = 0; i < 4; ++i)
      for (int k = 0; k < 4; ++k) P[i][k] *= double(i + 1) * (trial % 2 ? -3 : 0.5);
    const Result<Mat4d> c = solveProjectiveMap(M, P);
    ASSERT_TRUE(c.ok()) << trial << ": " << c.error().str();
    for (int i = 0; i < 5; ++i) {
      double r = 0;
      const Vec4d q = c.value() * M[size_t(i)];
      const double e = parallelError(q, P[size_t(i)], &r);
      worst = std::max(worst, e);
      EXPECT_LT(e, 1e-12) << trial << " point " << i + 1;
      // r_5 = 1: the fifth target is reached itself, scale included.
      if (i == 4) {
        EXPECT_NEAR(r, 1, 1e-12) << trial;
      }
    }
  }
  std::printf("five-point map: worst relative reproduction error %.3g over 200 random sets\n",
              worst);
}

TEST(FivePointMap, RecoversAPerspectiveProjectionFromFiveOfItsPointPairs) {
  // glFrustum's matrix (Mat4::frustum, in double): l, r, b, t on the near plane z = −n.
  const double l = -0.7, r = 0.4, b = -0.3, t = 0.5, n = 0.5, f = 2000;
  Mat4d proj;
  proj.m = {{{2 * n / (r - l), 0, (r + l) / (r - l), 0},
             {0, 2 * n / (t - b), (t + b) / (t - b), 0},
             {0, 0, -(f + n) / (f - n), -2 * f * n / (f - n)},
             {0, 0, -1, 0}}};
  // Five points of the frustum, no four coplanar: three near corners, a far corner, the axis.
  const std::array<Vec4d, 5> M = {Vec4d{{l, b, -n, 1}}, Vec4d{{r, b, -n, 1}}, Vec4d{{l, t, -n, 1}},
                                  Vec4d{{r * 100, t * 100, -100, 1}}, Vec4d{{0, 0, -7, 1}}};
  std::array<Vec4d, 5> P;
  for (size_t i = 0; i < 5; ++i) P[i] = proj * M[i];
  const Result<Mat4d> c = solveProjectiveMap(M, P);
  ASSERT_TRUE(c.ok()) << c.error().str();
  const double e = relativeDifference(c.value(), proj);
  std::printf("perspective projection recovered to %.3g relative\n", e);
  EXPECT_LT(e, 1e-12);
}

TEST(FivePointMap, RecoversARandomWellConditionedMapFromFiveOfItsPointPairs) {
  std::mt19937 rng(12);
  std::normal_distribution<double> g(0, 1);
  double worst = 0;
  for (int trial = 0; trial < 50; ++trial) {
    // Identity plus a perturbation of norm below one half: condition number at most 3.
    const Mat4d known = perturbedIdentity<Mat4d>(rng, 0.1);
    std::array<Vec4d, 5> M = {Vec4d{{1, 0, 0, 1}}, Vec4d{{0, 1, 0, 1}}, Vec4d{{0, 0, 1, 1}},
                              Vec4d{{0, 0, 0, 1}}, Vec4d{{1, 1, 1, 1}}};
    for (auto& p : M)
      for (int k = 0; k < 4; ++k) p[k] += 0.05 * g(rng);
    std::array<Vec4d, 5> P;
    for (size_t i = 0; i < 5; ++i) P[i] = known * M[i];
    const Result<Mat4d> c = solveProjectiveMap(M, P);
    ASSERT_TRUE(c.ok()) << c.error().str();
    const double e = relativeDifference(c.value(), known);
    worst = std::max(worst, e);
    EXPECT_LT(e, 1e-12) << trial;
  }
  std::printf("random well-conditioned maps recovered to %.3g relative (worst of 50)\n", worst);
}

TEST(FivePointMap, RefusesFourCoplanarPointsNamingThem) {
  std::array<Vec4d, 5> good = {Vec4d{{0, 0, 0, 1}}, Vec4d{{1, 0, 0, 1}}, Vec4d{{0, 1, 0, 1}},
                               Vec4d{{0, 0, 1, 1}}, Vec4d{{1, 1, 1, 1}}};
  ASSERT_TRUE(solveProjectiveMap(good, good).ok());
  // Points 1, 2, 3 and 5 in the plane z = 0.
  std::array<Vec4d, 5> flat = good;
  flat[4] = Vec4d{{1, 1, 0, 1}};
  const Result<Mat4d> a = solveProjectiveMap(flat, good);
  ASSERT_FALSE(a.ok());
  EXPECT_NE(a.error().message.find("source points 1, 2, 3 and 5 are coplanar"), std::string::npos)
      << a.error().str();
  const Result<Mat4d> b = solveProjectiveMap(good, flat);
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.error().message.find("target points 1, 2, 3 and 5 are coplanar"), std::string::npos)
      << b.error().str();
  // Nearly coplanar beyond double's reach is refused too; a millimetre off the plane is not.
  flat[4][2] = 1e-14;
  EXPECT_FALSE(solveProjectiveMap(flat, good).ok());
  flat[4][2] = 1e-3;
  EXPECT_TRUE(solveProjectiveMap(flat, good).ok());
  // Two equal points make every four that hold both coplanar.
  std::array<Vec4d, 5> twice = good;
  twice[3] = twice[1];
  EXPECT_FALSE(solveProjectiveMap(twice, good).ok());
  // The zero vector and non-finite numbers are not points.
  std::array<Vec4d, 5> zero = good;
  zero[0] = Vec4d{};
  const Result<Mat4d> z = solveProjectiveMap(zero, good);
  ASSERT_FALSE(z.ok());
  EXPECT_EQ(z.error().message, "source point 1 is zero: not a point");
  std::array<Vec4d, 5> nan = good;
  nan[2][1] = std::nan("");
  EXPECT_FALSE(solveProjectiveMap(good, nan).ok());
}

TEST(Homography, ReproducesFourPairsAndRecoversAKnownHomography) {
  std::mt19937 rng(7);
  std::normal_distribution<double> g(0, 1);
  double worst = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const Mat3d known = perturbedIdentity<Mat3d>(rng, 0.2);
    std::array<Vec3d, 4> M = {Vec3d{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    for (auto& p : M) p = {p.x + 0.05 * g(rng), p.y + 0.05 * g(rng), 1};
    std::array<Vec3d, 4> P;
    for (size_t i = 0; i < 4; ++i) P[i] = known * M[i];
    const Result<Mat3d> h = solveHomography(M, P);
    ASSERT_TRUE(h.ok()) << h.error().str();
    const double e = relativeDifference(h.value(), known);
    worst = std::max(worst, e);
    EXPECT_LT(e, 1e-12) << trial;
    // Each pair reproduced: H·M^i parallel to P^i.
    for (size_t i = 0; i < 4; ++i) {
      const Vec3d q = h.value() * M[i];
      const double s = dot(q, P[i]) / dot(P[i], P[i]);
      EXPECT_LT(norm(q - P[i] * s) / norm(q), 1e-12);
    }
  }
  std::printf("homographies recovered to %.3g relative (worst of 50)\n", worst);
}

TEST(Homography, RefusesThreeCollinearPointsNamingThem) {
  const std::array<Vec3d, 4> square = {Vec3d{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  std::array<Vec3d, 4> line = square;
  line[2] = {2, 0, 1};  // 1, 2 and 3 on y = 0
  const Result<Mat3d> h = solveHomography(line, square);
  ASSERT_FALSE(h.ok());
  EXPECT_NE(h.error().message.find("source points 1, 2 and 3 are collinear"), std::string::npos)
      << h.error().str();
  EXPECT_FALSE(solveHomography(square, line).ok());
}

TEST(Mat3d, InverseTimesMatrixIsTheIdentity) {
  Mat3d a;
  a.m = {{{2, 1, 0}, {0.5, 3, -1}, {0.25, 0, 1}}};
  const std::optional<Mat3d> inv = a.inverse();
  ASSERT_TRUE(inv);
  const Mat3d id = a * *inv;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(id.m[size_t(r)][size_t(c)], r == c ? 1 : 0, 1e-15);
  Mat3d singular;
  singular.m = {{{1, 2, 3}, {2, 4, 6}, {0, 0, 1}}};
  EXPECT_FALSE(singular.inverse());
}

}  // namespace
}  // namespace sv
