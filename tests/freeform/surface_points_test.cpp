// SurfacePoints (SPEC §12, the leaf's point and normal): the SIMD lanes give what the scalar
// transformPoint, FreeForm::gradient and normalize give, bit for bit, on every compiled target —
// for a form with a dent, a nested bump and clips (whose gradient is the active term's) — also
// leaving out the perturbations a bound about the points rules out.
#include "freeform/surface_points.h"

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "every_target.h"

namespace sv::freeform {
namespace {

TEST(SurfacePoints, LanesEqualTheScalarFormulasOnEveryTarget) {
  FreeForm f;
  f.base = Quadric::sphere({0, 0, 0}, 1);
  FreeForm bump, inner, dent;
  bump.base = Quadric::sphere({0.9, 0, 0}, 0.5);
  inner.base = Quadric::ellipsoid({1.1, 0.2, 0}, {0.3, 0.2, 0.25});
  bump.perturbations.push_back(inner);
  dent.base = Quadric::cylinder({0, 0.8, 0}, {0, 0, 1}, 0.3);
  dent.weight = -4;
  f.perturbations = {bump, dent};
  f.clips = {Quadric::halfSpace({0, 1, 0}, 0.5)};
  // Cube → object: a perspective frustum's inverse; object → eye: a rotation and a shift.
  std::array<Vec3d, 5> frustum = {
      Vec3d{-1, -1, 3}, {1, -1, 3}, {-1, 1, 3}, {-5, -5, -1}, {5, 5, -1}};
  std::array<Vec3d, 5> cube = {Vec3d{-1, -1, -1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}, {1, 1, 1}};
  const Mat4d toCube = *projectiveFromFivePoints(frustum, cube);
  const Mat4d cubeToObject = *toCube.inverse();
  Mat4d toEye;
  toEye.m = {{{0.8, 0, 0.6, 0.5}, {0, 1, 0, -0.2}, {-0.6, 0, 0.8, -4}, {0, 0, 0, 1}}};
  const Mat4d normalToEye = toEye.inverse()->transposed();
  const SurfacePoints surface(f, cubeToObject, toEye, normalToEye, 2.0, 0.5);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1.3, 1.3);
  int clipped = 0, bumped = 0, ruledOut = 0;
  const std::optional<ProjectedFreeForm> projected = ProjectedFreeForm::make(f, toCube);
  ASSERT_TRUE(projected);
  const int targets = forEveryTarget([&](int64_t target) {
    for (int round = 0; round < 300; ++round) {
      const int count = 1 + round % 16;
      double x[16], y[16], z[16];
      for (int i = 0; i < count; ++i) {  // the cube points of object points about the form
        const Vec3d q = toCube.transformPoint({u(rng), u(rng), u(rng)});
        x[i] = q.x, y[i] = q.y, z[i] = q.z;
      }
      SurfaceLanes out, masked;
      surface.at(x, y, z, count, out);
      // Leaving out the perturbations a box about the points rules out changes no bit.
      Interval bx{x[0], x[0]}, by{y[0], y[0]}, bz{z[0], z[0]};
      for (int i = 1; i < count; ++i) {
        bx = {std::min(bx.lo, x[i]), std::max(bx.hi, x[i])};
        by = {std::min(by.lo, y[i]), std::max(by.hi, y[i])};
        bz = {std::min(bz.lo, z[i]), std::max(bz.hi, z[i])};
      }
      Interval value, slope;
      uint64_t active = kAllActive;
      projected->bound(bx, by, bz, value, slope, &active);
      ruledOut += active != kAllActive ? 1 : 0;
      surface.at(x, y, z, count, masked, active);
      for (int k = 0; k < 3; ++k)
        for (int i = 0; i < count; ++i) {
          EXPECT_EQ(masked.normal[k][i], out.normal[k][i]) << "round " << round;
          EXPECT_EQ(masked.gradient[k][i], out.gradient[k][i]) << "round " << round;
        }
      for (int i = 0; i < count; ++i) {
        const Vec3d p = cubeToObject.transformPoint({x[i], y[i], z[i]});
        const Vec3d g = f.gradient(p);
        const Vec3d m = g * -1.0;
        const Vec3d n = normalize(Vec3d{
            normalToEye.m[0][0] * m.x + normalToEye.m[0][1] * m.y + normalToEye.m[0][2] * m.z,
            normalToEye.m[1][0] * m.x + normalToEye.m[1][1] * m.y + normalToEye.m[1][2] * m.z,
            normalToEye.m[2][0] * m.x + normalToEye.m[2][1] * m.y + normalToEye.m[2][2] * m.z});
        const Vec3d e = toEye.transformPoint(p);
        const Vec3d want[4] = {p, g, n, e};
        const double(*got[4])[16] = {out.point, out.gradient, out.normal, out.eye};
        for (int k = 0; k < 4; ++k) {
          EXPECT_EQ(got[k][0][i], want[k].x)
              << hwy::TargetName(target) << " " << k << " lane " << i;
          EXPECT_EQ(got[k][1][i], want[k].y)
              << hwy::TargetName(target) << " " << k << " lane " << i;
          EXPECT_EQ(got[k][2][i], want[k].z)
              << hwy::TargetName(target) << " " << k << " lane " << i;
        }
        // The floats shading reads: the doubles rounded (u, v scaled by 2 and 0.5).
        EXPECT_EQ(out.floats[out.kU][i], float(p.x * 2.0));
        EXPECT_EQ(out.floats[out.kV][i], float(p.z * 0.5));
        for (int c = 0; c < 3; ++c) {
          EXPECT_EQ(out.floats[out.kNormal + c][i], float(out.normal[c][i]));
          EXPECT_EQ(out.floats[out.kEye + c][i], float(out.eye[c][i]));
        }
        clipped += f.clips[0].evaluate(p) < f.base.evaluate(p) ? 1 : 0;
        bumped += bump.evaluate(p) > 0 ? 1 : 0;
      }
    }
  });
  EXPECT_GE(targets, 1);
  // The clip's gradient and the perturbations' terms were both exercised.
  EXPECT_GT(clipped, 50 * targets);
  EXPECT_GT(bumped, 20 * targets);
  EXPECT_GT(ruledOut, 20 * targets);  // and perturbations were left out
}

}  // namespace
}  // namespace sv::freeform
