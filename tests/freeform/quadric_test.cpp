// Quadrics and perturbed quadrics (SPEC §11–§12): the convenience forms against their definitions,
// the projective transform of a quadric against point evaluation, the five-point projective map,
// interval bounds containing sampled values (property tests), gradients against differences, and
// the perturbation's continuity where Q crosses 0; the SIMD slab bounds against the scalar bound.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cmath>
#include <random>
#include <string>

#include "every_target.h"
#include "freeform/freeform.h"

namespace sv::freeform {
namespace {

Vec3d randomPoint(std::mt19937& rng, double r) {
  std::uniform_real_distribution<double> u(-r, r);
  return {u(rng), u(rng), u(rng)};
}

// A sculpture-like form: a sphere with two bumps, one of them bumped again.
FreeForm bumpySphere() {
  FreeForm f;
  f.base = Quadric::sphere({0, 0, 0}, 1);
  FreeForm bump;
  bump.base = Quadric::sphere({0.9, 0, 0}, 0.5);
  FreeForm inner;
  inner.base = Quadric::ellipsoid({1.1, 0.2, 0}, {0.3, 0.2, 0.25});
  bump.perturbations.push_back(inner);
  FreeForm dent;
  dent.base = Quadric::cylinder({0, 0.8, 0}, {0, 0, 1}, 0.3);
  dent.weight = -4;
  f.perturbations = {bump, dent};
  return f;
}

// The map of a perspective frustum — a camera at z = 4 looking down −z — onto the cube.
Mat4d frustumToCube() {
  const std::array<Vec3d, 5> frustum = {
      Vec3d{-1, -1, 3}, {1, -1, 3}, {-1, 1, 3}, {-5, -5, -1}, {5, 5, -1}};
  const std::array<Vec3d, 5> cube = {
      Vec3d{-1, -1, -1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}, {1, 1, 1}};
  return *projectiveFromFivePoints(frustum, cube);
}

// A capped cylinder: the cylinder's inside cut by two half-spaces; the gradient is the active
// term's.
TEST(Quadric, ClipsIntersectInsides) {
  FreeForm f;
  f.base = Quadric::cylinder({0, 0, 0}, {0, 1, 0}, 1);
  f.clips = {Quadric::halfSpace({0, 1, 0}, 1), Quadric::halfSpace({0, -1, 0}, 1)};
  EXPECT_GT(f.evaluate({0, 0, 0}), 0);
  EXPECT_LT(f.evaluate({0, 1.5, 0}), 0);  // above the cap
  EXPECT_LT(f.evaluate({1.5, 0, 0}), 0);  // outside the side
  EXPECT_NEAR(f.evaluate({0, 1, 0}), 0, 1e-12);
  const Vec3d top = f.gradient({0, 0.99, 0});  // nearest the top cap: −∇ points up
  EXPECT_NEAR(top.y, -1, 1e-12);
  const Vec3d side = f.gradient({0.99, 0, 0});
  EXPECT_LT(side.x, 0);
  EXPECT_EQ(side.y, 0);
}

TEST(Quadric, FormsAreZeroOnTheirSurfacesAndPositiveInside) {
  const double s2 = std::sqrt(2.0);
  struct Case {
    const char* name;
    Quadric q;
    Vec3d on, in, out;
  };
  const Case cases[] = {
      {"sphere", Quadric::sphere({1, 2, 3}, 2), {3, 2, 3}, {1, 2, 3}, {1, 4.5, 3}},
      {"ellipsoid", Quadric::ellipsoid({0, 0, 0}, {1, 2, 3}), {0, 0, 3}, {0.5, 0, 0}, {0, 2.1, 0}},
      {"cylinder",
       Quadric::cylinder({0, 0, 0}, {0, 0, 5}, 1),
       {1 / s2, 1 / s2, 7},
       {0.2, 0, -9},
       {1, 1, 0}},
      {"cone", Quadric::cone({0, 0, 0}, {0, 1, 0}, M_PI / 4), {1, 1, 0}, {0, 2, 0.5}, {2, 1, 0}},
      {"paraboloid",
       Quadric::paraboloid({0, -1, 0}, {0, 1, 0}, 2),
       {1, 1, 0},
       {0, 0, 0},
       {2, 0, 0}},
      {"half-space", Quadric::halfSpace({0, 0, 2}, 2), {5, -3, 1}, {0, 0, 0}, {0, 0, 1.5}},
  };
  for (const Case& c : cases) {
    EXPECT_NEAR(c.q.evaluate(c.on), 0, 1e-12) << c.name;
    EXPECT_GT(c.q.evaluate(c.in), 0) << c.name;
    EXPECT_LT(c.q.evaluate(c.out), 0) << c.name;
    EXPECT_TRUE(Quadric::fromMatrix(c.q.matrix()).c == c.q.c) << c.name;
  }
  // The half-space's value is the signed distance to its plane.
  EXPECT_NEAR(Quadric::halfSpace({0, 0, 2}, 2).evaluate({0, 0, -3}), 4, 1e-12);
}

TEST(Quadric, GradientsMatchCentralDifferences) {
  std::mt19937 rng(1);
  const FreeForm f = bumpySphere();
  for (int i = 0; i < 200; ++i) {
    const Vec3d p = randomPoint(rng, 1.5);
    const Vec3d g = f.gradient(p);
    const double h = 1e-6;
    const double dx = (f.evaluate(p + Vec3d{h, 0, 0}) - f.evaluate(p - Vec3d{h, 0, 0})) / (2 * h);
    const double dy = (f.evaluate(p + Vec3d{0, h, 0}) - f.evaluate(p - Vec3d{0, h, 0})) / (2 * h);
    const double dz = (f.evaluate(p + Vec3d{0, 0, h}) - f.evaluate(p - Vec3d{0, 0, h})) / (2 * h);
    EXPECT_NEAR(g.x, dx, 1e-5 * (1 + std::fabs(dx)));
    EXPECT_NEAR(g.y, dy, 1e-5 * (1 + std::fabs(dy)));
    EXPECT_NEAR(g.z, dz, 1e-5 * (1 + std::fabs(dz)));
  }
}

// R = Q³ where Q ≥ 0 (SPEC §11): across Q = 0 the value, gradient and second derivative of the
// perturbed form are continuous — no crack, no crease.
TEST(Quadric, PerturbationIsContinuousWhereQCrossesZero) {
  FreeForm f;
  f.base = Quadric::halfSpace({0, 1, 0}, 0);  // the ground y ≤ 0
  FreeForm bump;
  bump.base = Quadric::sphere({0, 0, 0}, 1);
  f.perturbations.push_back(bump);
  // Along x through the bump's rim at x = 1 (y = 0.3): Q = 1 − x² − 0.09 crosses 0 at x ≈ 0.954.
  const double x0 = std::sqrt(1 - 0.09);
  for (double eps : {1e-3, 1e-5}) {
    const Vec3d a{x0 - eps, 0.3, 0}, b{x0 + eps, 0.3, 0};
    EXPECT_NEAR(f.evaluate(a), f.evaluate(b), 10 * eps * eps * eps + 1e-15) << eps;
    EXPECT_NEAR(f.gradient(a).x, f.gradient(b).x, 100 * eps * eps) << eps;
  }
}

TEST(Quadric, ProjectiveTransformAgreesWithPointEvaluation) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 50; ++trial) {
    Mat4d m;
    for (auto& row : m.m)
      for (double& v : row) v = u(rng);
    for (int i = 0; i < 4; ++i) m.m[i][i] += 2.5;  // well conditioned
    const std::optional<Mat4d> inv = m.inverse();
    ASSERT_TRUE(inv);
    Quadric q;
    for (double& c : q.c) c = u(rng);
    const Quadric t = q.transformedByInverse(*inv);
    for (int k = 0; k < 20; ++k) {
      const Vec3d p = randomPoint(rng, 1);
      const Vec4d image = m * Vec4d{{p.x, p.y, p.z, 1}};
      if (std::fabs(image[3]) < 0.1) continue;
      const Vec3d qp{image[0] / image[3], image[1] / image[3], image[2] / image[3]};
      const double uw = 1 / image[3];  // the w of M⁻¹·(q, 1)
      EXPECT_NEAR(t.evaluate(qp), uw * uw * q.evaluate(p), 1e-9 * (1 + std::fabs(uw * uw)));
    }
  }
}

TEST(Projective, FivePointPairsFixTheMapWhichReproducesThemAndInvertsExactly) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 100; ++trial) {
    std::array<Vec3d, 5> src, dst;
    for (auto& p : src) p = randomPoint(rng, 2);
    for (auto& p : dst) p = randomPoint(rng, 2);
    const std::optional<Mat4d> m = projectiveFromFivePoints(src, dst);
    ASSERT_TRUE(m) << trial;
    const std::optional<Mat4d> inv = m->inverse();
    ASSERT_TRUE(inv);
    for (int i = 0; i < 5; ++i) {
      const Vec3d a = m->transformPoint(src[size_t(i)]), b = inv->transformPoint(dst[size_t(i)]);
      for (double d : {a.x - dst[size_t(i)].x, a.y - dst[size_t(i)].y, a.z - dst[size_t(i)].z,
                       b.x - src[size_t(i)].x, b.y - src[size_t(i)].y, b.z - src[size_t(i)].z})
        EXPECT_NEAR(d, 0, 1e-7) << trial << " point " << i;
    }
    // M·M⁻¹ is the identity.
    const Mat4d id = *m * *inv;
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) EXPECT_NEAR(id.m[r][c], r == c ? 1 : 0, 1e-9);
  }
  // The view frustum onto the cube: the map a perspective projection makes, recovered from five
  // of the frustum's corners.
  std::array<Vec3d, 5> frustum = {
      Vec3d{-1, -1, -1}, {1, -1, -1}, {-1, 1, -1}, {-10, -10, -10}, {10, 10, -10}};
  std::array<Vec3d, 5> cube = {Vec3d{-1, -1, -1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}, {1, 1, 1}};
  const std::optional<Mat4d> p = projectiveFromFivePoints(frustum, cube);
  ASSERT_TRUE(p);
  const Vec3d far = p->transformPoint({10, -10, -10});  // the sixth corner follows
  EXPECT_NEAR(far.x, 1, 1e-9);
  EXPECT_NEAR(far.y, -1, 1e-9);
  EXPECT_NEAR(far.z, 1, 1e-9);
  // Four coplanar points fix no map.
  std::array<Vec3d, 5> flat = {Vec3d{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 1}};
  EXPECT_FALSE(projectiveFromFivePoints(flat, cube));
  EXPECT_FALSE(projectiveFromFivePoints(cube, flat));
}

// Property test: the bound of every box contains the function at points sampled inside it — for
// quadrics, perturbed forms, and their projected versions.
TEST(Interval, BoundsContainSampledValues) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(0, 1);
  FreeForm f = bumpySphere();
  // Cut by two clips as well (set-theoretic intersection): min(F', C_1, C_2).
  f.clips = {Quadric::halfSpace({0, 1, 0}, 0.7), Quadric::cylinder({0, 0, 0}, {0, 1, 0}, 1.1)};
  // A perspective map: the frustum of a camera at z = 4 looking down −z onto the cube.
  const std::optional<ProjectedFreeForm> g = ProjectedFreeForm::make(f, frustumToCube());
  ASSERT_TRUE(g);
  for (int trial = 0; trial < 2000; ++trial) {
    const double size = std::exp2(-u(rng) * 10);
    const Vec3d lo = randomPoint(rng, 1.2);
    const Interval x{lo.x, lo.x + size * u(rng)}, y{lo.y, lo.y + size * u(rng)},
        z{lo.z, lo.z + size * u(rng)};
    const Interval bf = f.bound(x, y, z), bg = g->bound(x, y, z);
    for (int k = 0; k < 8; ++k) {
      const Vec3d p{x.lo + (x.hi - x.lo) * u(rng), y.lo + (y.hi - y.lo) * u(rng),
                    z.lo + (z.hi - z.lo) * u(rng)};
      const double vf = f.evaluate(p), vg = g->evaluate(p);
      EXPECT_LE(bf.lo, vf);
      EXPECT_GE(bf.hi, vf);
      EXPECT_LE(bg.lo, vg);
      EXPECT_GE(bg.hi, vg);
    }
  }
}

// The bumpy sphere cut by a half-space, in the frustum's cube.
ProjectedFreeForm clippedBumpySphere() {
  FreeForm f = bumpySphere();
  f.clips = {Quadric::halfSpace({0, 1, 0}, 0.7)};
  return *ProjectedFreeForm::make(f, frustumToCube());
}

// The SIMD slab bounds (slab_bounds.cpp) answer as the scalar bound does, slab by slab, on every
// compiled target — for boxes of every size, a form with a dent, a nested bump and clips, and
// boxes reaching behind the eye (u ≤ 0), where the bound is everything — and leaving out the
// perturbations they rule out over a box changes no answer.
TEST(Projected, SlabBoundsEqualTheScalarBoundOnEveryTarget) {
  const ProjectedFreeForm form = clippedBumpySphere();
  const ProjectedFreeForm* g = &form;
  const int targets = forEveryTarget([&](int64_t target) {
    std::mt19937 rng(6);
    std::uniform_real_distribution<double> u(0, 1);
    int held = 0, rejected = 0, ruledOut = 0;
    for (int trial = 0; trial < 3000; ++trial) {
      const double size = std::exp2(-u(rng) * 8);
      const Vec3d lo = randomPoint(rng, 1.1);
      const Interval x{lo.x, lo.x + size * u(rng)}, y{lo.y, lo.y + size * u(rng)};
      // Depth ranges reach behind the eye (cube z < −1.75 here is u ≤ 0) in some trials.
      const double zlo = trial % 10 == 0 ? -3 + u(rng) : lo.z, zhi = zlo + 2 * size * u(rng) + 1e-9;
      const int count = 1 + trial % 16;
      bool holds[16], again[16];
      uint64_t active = 0;
      g->slabsHolding(x, y, zlo, zhi, count, holds, kAllActive, &active);
      // Leaving out the perturbations ruled out over the box changes no answer.
      g->slabsHolding(x, y, zlo, zhi, count, again, active);
      ruledOut += active != kAllActive ? 1 : 0;
      for (int s = 0; s < count; ++s) {
        const Interval z{zlo + (zhi - zlo) * s / count, zlo + (zhi - zlo) * (s + 1) / count};
        const bool expected = g->bound(x, y, z).containsZero();
        EXPECT_EQ(holds[s], expected)
            << hwy::TargetName(target) << " trial " << trial << " slab " << s;
        EXPECT_EQ(again[s], expected)
            << hwy::TargetName(target) << " trial " << trial << " slab " << s;
        (expected ? held : rejected) += 1;
      }
      // The scalar bound with its slope, over the whole box, leaving them out (the slabs rule out
      // more than one bound over the box can): still holding H there.
      Interval value, slope, value2, slope2;  // without and with `active`
      uint64_t positive = kAllActive, positive2 = active;
      g->bound(x, y, {zlo, zhi}, value, slope, &positive);
      g->bound(x, y, {zlo, zhi}, value2, slope2, &positive2);
      EXPECT_EQ(positive2, positive & active) << "trial " << trial;
      if (zlo > -1.5) {  // in front of the eye: finite bounds
        for (int k = 0; k < 8; ++k) {
          const double h = g->evaluate({x.lo + (x.hi - x.lo) * u(rng),
                                        y.lo + (y.hi - y.lo) * u(rng), zlo + (zhi - zlo) * u(rng)});
          EXPECT_TRUE(value2.lo <= h && h <= value2.hi) << "trial " << trial;
        }
      }
    }
    // Both answers occur often: the comparison is not vacuous.
    EXPECT_GT(held, 300);
    EXPECT_GT(rejected, 1000);
    EXPECT_GT(ruledOut, 300);  // perturbations were left out often
  });
  EXPECT_GE(targets, 1);
}

// The SIMD window bounds (boundWindows) are the scalar bound with its slope and perturbation mask,
// bit for bit, window by window, on every compiled target — with and without a mask to take,
// for windows reaching behind the eye too.
TEST(Projected, WindowBoundsEqualTheScalarBoundOnEveryTarget) {
  const ProjectedFreeForm form = clippedBumpySphere();
  const ProjectedFreeForm* g = &form;
  const int targets = forEveryTarget([&](int64_t target) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0, 1);
    int holding = 0, monotonic = 0, ruledOut = 0;
    for (int trial = 0; trial < 500; ++trial) {
      const int count = 1 + trial % 16;
      // Windows about a point of the sphere the bumps sit on (some behind the eye).
      const double size = std::exp2(-4 - u(rng) * 6);
      const Vec3d r = randomPoint(rng, 1);
      const Vec3d c = frustumToCube().transformPoint(r * (1 / std::sqrt(dot(r, r))));
      const double zlo = trial % 10 == 0 ? -3 + u(rng) : c.z - size * u(rng);
      const Interval z{zlo, zlo + 2 * size * u(rng) + 1e-9};
      const uint64_t take = trial % 3 == 0 ? ~uint64_t(2) : kAllActive;
      Interval x[16], y[16], value[16], slope[16];
      uint64_t active[16];
      for (int i = 0; i < count; ++i) {
        const double x0 = c.x + 4 * size * (u(rng) - 0.5), y0 = c.y + 4 * size * (u(rng) - 0.5);
        x[i] = {x0, x0 + size * u(rng)};
        y[i] = {y0, y0 + size * u(rng)};
      }
      g->boundWindows(x, y, count, z, take, value, slope, active);
      for (int i = 0; i < count; ++i) {
        Interval v, s;
        uint64_t a = take;
        g->bound(x[i], y[i], z, v, s, &a);
        const std::string where =
            std::string(hwy::TargetName(target)) + " trial " + std::to_string(trial);
        EXPECT_EQ(value[i].lo, v.lo) << where;
        EXPECT_EQ(value[i].hi, v.hi) << where;
        EXPECT_EQ(slope[i].lo, s.lo) << where;
        EXPECT_EQ(slope[i].hi, s.hi) << where;
        EXPECT_EQ(active[i], a) << where;
        holding += v.containsZero() ? 1 : 0;
        monotonic += v.containsZero() && !s.containsZero() ? 1 : 0;
        ruledOut += a != take ? 1 : 0;
      }
    }
    EXPECT_GT(holding, 100);  // the windows meet the surface, monotonic or not, often enough
    EXPECT_GT(monotonic, 20);
    EXPECT_GT(ruledOut, 200);
  });
  EXPECT_GE(targets, 1);
}

// A ray without the perturbations a box's bound rules out (ProjectedFreeForm::ray's `active`) is
// the same function inside the box, value and slope, bit for bit — and the form's own value.
TEST(Projected, RaysWithoutRuledOutPerturbationsAreTheSameFunction) {
  const FreeForm f = bumpySphere();
  const std::optional<ProjectedFreeForm> g = ProjectedFreeForm::make(f, frustumToCube());
  ASSERT_TRUE(g);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  int ruledOut = 0;
  RayFunction all, some;
  const Mat4d toCube = frustumToCube();
  int differs = 0;  // samples where the bump is positive: leaving it out would change H there
  for (int trial = 0; trial < 2000; ++trial) {
    // Small boxes about points in the bump (object centre (0.9, 0, 0), radius 0.5).
    const double size = std::exp2(-3 - u(rng) * 5);
    const Vec3d c = toCube.transformPoint(Vec3d{0.9, 0, 0} + randomPoint(rng, 0.35));
    const Interval x{c.x - size / 2, c.x + size / 2}, y{c.y - size / 2, c.y + size / 2},
        z{c.z - size / 2, c.z + size / 2};
    Interval value, slope;
    uint64_t active = kAllActive;
    g->bound(x, y, z, value, slope, &active);
    if (active == kAllActive) continue;
    ++ruledOut;
    for (int k = 0; k < 4; ++k) {
      const double rx = x.lo + size * u(rng), ry = y.lo + size * u(rng), rz = z.lo + size * u(rng);
      g->ray(rx, ry, all);
      g->ray(rx, ry, some, active);
      double s1, s2;
      EXPECT_EQ(all.evaluate(rz, s1), some.evaluate(rz, s2)) << "trial " << trial;
      EXPECT_EQ(s1, s2) << "trial " << trial;
      EXPECT_EQ(all.evaluate(rz), some.evaluate(rz)) << "trial " << trial;
      const double h = g->evaluate({rx, ry, rz});  // the form itself, at the point
      EXPECT_NEAR(some.evaluate(rz), h, 1e-9 * (1 + std::fabs(h))) << "trial " << trial;
      RayFunction base;  // every perturbation left out
      g->ray(rx, ry, base, 0);
      differs += all.evaluate(rz) != base.evaluate(rz) ? 1 : 0;
    }
  }
  EXPECT_GT(ruledOut, 500);
  EXPECT_GT(differs, 500);  // the perturbations kept matter where they were kept
}

// The projected form has the object's surface and inside: H = u²·F' at corresponding points.
TEST(Projected, HasTheSameSignAsTheObjectFormAtCorrespondingPoints) {
  const FreeForm f = bumpySphere();
  const Mat4d m = frustumToCube();
  const std::optional<ProjectedFreeForm> g = ProjectedFreeForm::make(f, m);
  ASSERT_TRUE(g);
  std::mt19937 rng(5);
  for (int i = 0; i < 500; ++i) {
    const Vec3d q = randomPoint(rng, 1);
    const Vec3d p = g->toObject(q);
    const Vec4d h = g->inverse() * Vec4d{{q.x, q.y, q.z, 1}};
    const double u2 = h[3] * h[3];
    EXPECT_NEAR(g->evaluate(q), u2 * f.evaluate(p), 1e-9 * (1 + std::fabs(u2 * f.evaluate(p))));
  }
}

}  // namespace
}  // namespace sv::freeform
