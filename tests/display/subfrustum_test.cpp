// Method (a)'s plan: cells with projective maps tile the display, reach the residual bound on the
// 3-projector cylinder rig, report their true maximum error (checked by an independent brute
// force through the 4×4 projection), cover their pixels with their frusta, and follow the eye.
#include "display/subfrustum.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "display/resample.h"

namespace sv::display {
namespace {

constexpr double kToRadians = std::numbers::pi / 180;

// A plain pinhole camera's mapping in double: the flat display.
DirectionTable pinholeTable(const Orientation& o, const Window& w, int width, int height) {
  const Rotation r = rotationOf(o);
  const WindowTangents t = tangentsOf(w);
  DirectionTable table;
  table.width = width;
  table.height = height;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const double b[3] = {t.left + (x + 0.5) / width * (t.right - t.left),
                           t.up - (y + 0.5) / height * (t.up - t.down), -1};
      Vec3d d;
      d.x = r.m[0][0] * b[0] + r.m[0][1] * b[1] + r.m[0][2] * b[2];
      d.y = r.m[1][0] * b[0] + r.m[1][1] * b[1] + r.m[1][2] * b[2];
      d.z = r.m[2][0] * b[0] + r.m[2][1] * b[1] + r.m[2][2] * b[2];
      table.directions.push_back(normalize(d));
      table.valid.push_back(1);
    }
  return table;
}

// Every valid pixel centre in exactly one cell, cells inside the display, none wholly invalid.
void expectTiling(const SubFrustumPlan& plan, const DirectionTable& t) {
  std::vector<int> owners(size_t(t.width) * size_t(t.height), 0);
  for (const SubFrustumCell& c : plan.cells) {
    ASSERT_TRUE(c.x0 >= 0 && c.x0 < c.x1 && c.x1 <= t.width && c.y0 >= 0 && c.y0 < c.y1 &&
                c.y1 <= t.height);
    int64_t valid = 0;
    for (int y = c.y0; y < c.y1; ++y)
      for (int x = c.x0; x < c.x1; ++x) {
        ++owners[t.index(x, y)];
        valid += t.valid[t.index(x, y)];
      }
    EXPECT_GT(valid, 0) << "a wholly invalid cell was kept";
    EXPECT_EQ(valid, c.validPixels);
  }
  int64_t gaps = 0, doubles = 0;
  for (size_t i = 0; i < owners.size(); ++i) {
    gaps += t.valid[i] && owners[i] == 0;
    doubles += owners[i] > 1;
  }
  EXPECT_EQ(gaps, 0);
  EXPECT_EQ(doubles, 0);
}

// The residuals of one cell measured another way: through its 4×4 projection (clip → pixel) for
// the pixel error, and through that matrix's inverse (unprojecting the pixel centre) for the angle.
struct Residual {
  double pixels = 0, radians = 0;
};
Residual bruteForce(const SubFrustumCell& c, const DirectionTable& t) {
  Residual r;
  const std::optional<Mat4d> inverse = c.projection.inverse();
  EXPECT_TRUE(inverse);
  for (int y = c.y0; y < c.y1; ++y)
    for (int x = c.x0; x < c.x1; ++x) {
      if (!t.valid[t.index(x, y)]) continue;
      const Vec3d d = t.directions[t.index(x, y)];
      const Vec4d clip = c.projection * Vec4d{{d.x, d.y, d.z, 1}};
      const double px = c.x0 + (clip[0] / clip[3] + 1) / 2 * (c.x1 - c.x0);
      const double py = c.y0 + (1 - clip[1] / clip[3]) / 2 * (c.y1 - c.y0);
      r.pixels = std::max(r.pixels, std::hypot(px - (x + 0.5), py - (y + 0.5)));
      const double nx = 2 * (x + 0.5 - c.x0) / (c.x1 - c.x0) - 1;
      const double ny = 1 - 2 * (y + 0.5 - c.y0) / (c.y1 - c.y0);
      const Vec3d m = normalize(inverse->transformPoint({nx, ny, 0}));
      r.radians = std::max(r.radians, std::acos(std::clamp(dot(d, m), -1.0, 1.0)));
    }
  return r;
}

double millisecondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

TEST(SubFrustum, AFlatDisplayIsOneCellWithNoResidual) {
  const DirectionTable t = pinholeTable({20, -5, 3}, {-40, 25, -18, 30}, 640, 400);
  const SubFrustumPlan plan = planSubFrusta(t);
  ASSERT_EQ(plan.cells.size(), 1u);
  const SubFrustumCell& c = plan.cells[0];
  EXPECT_EQ(c.x0, 0);
  EXPECT_EQ(c.y0, 0);
  EXPECT_EQ(c.x1, 640);
  EXPECT_EQ(c.y1, 400);
  std::printf("flat 640 x 400 display: 1 cell, residual %.3g px, %.3g rad\n", c.residualPixels,
              c.residualRadians);
  EXPECT_LT(c.residualPixels, 1e-9);
  EXPECT_LT(c.residualRadians, 1e-12);
}

TEST(SubFrustum, TheCylinderRigsProjectorsReachTheBound) {
  const CylinderRig rig = threeProjectorCylinder();  // 1280 × 800 projectors
  for (int i = 0; i < 3; ++i) {
    const DirectionTable t = directionTable(rig.geometry(i));
    const auto t0 = std::chrono::steady_clock::now();
    const SubFrustumPlan plan = planSubFrusta(t);
    const double ms = millisecondsSince(t0);
    EXPECT_EQ(plan.cellsAboveBound, 0);
    EXPECT_EQ(plan.unfittedPixels, 0);
    EXPECT_LE(plan.maxResidualPixels, 0.1);
    expectTiling(plan, t);
    size_t smallest = 1 << 30;
    for (const SubFrustumCell& c : plan.cells) smallest = std::min(smallest, size_t(c.x1 - c.x0));
    std::printf(
        "projector %d (1280 x 800): %zu cells (narrowest %zu px), max residual %.4f px = "
        "%.3g rad, planned in %.1f ms\n",
        i, plan.cells.size(), smallest, plan.maxResidualPixels, plan.maxResidualRadians, ms);
  }
  // A tighter bound needs more cells.
  const DirectionTable t = directionTable(rig.geometry(0));
  SubFrustumOptions tight;
  tight.boundPixels = 0.01;
  const SubFrustumPlan a = planSubFrusta(t), b = planSubFrusta(t, tight);
  EXPECT_GT(b.cells.size(), a.cells.size());
  EXPECT_LE(b.maxResidualPixels, 0.01);
  std::printf("projector 0 at 0.01 px: %zu cells, max residual %.4f px\n", b.cells.size(),
              b.maxResidualPixels);
}

TEST(SubFrustum, ReportedResidualIsTheTrueMaximumByBruteForce) {
  const CylinderRig rig = threeProjectorCylinder(3, 10, 320, 200);
  const DirectionTable t = directionTable(rig.geometry(2));
  SubFrustumOptions o;
  o.boundPixels = 0.02;
  const SubFrustumPlan plan = planSubFrusta(t, o);
  ASSERT_GT(plan.cells.size(), 1u);
  Residual worst;
  for (const SubFrustumCell& c : plan.cells) {
    const Residual r = bruteForce(c, t);
    EXPECT_NEAR(c.residualPixels, r.pixels, 1e-9 + 1e-6 * r.pixels);
    EXPECT_NEAR(c.residualRadians, r.radians, 1e-9 + 1e-4 * r.radians);  // acos near 0: coarser
    worst.pixels = std::max(worst.pixels, r.pixels);
    worst.radians = std::max(worst.radians, r.radians);
  }
  EXPECT_NEAR(plan.maxResidualPixels, worst.pixels, 1e-9 + 1e-6 * worst.pixels);
  std::printf(
      "320 x 200 at 0.02 px: %zu cells, reported %.6f px / %.4g rad, brute force %.6f px "
      "/ %.4g rad\n",
      plan.cells.size(), plan.maxResidualPixels, plan.maxResidualRadians, worst.pixels,
      worst.radians);
}

TEST(SubFrustum, ProjectionIsTheFivePointMapOfItsCorners) {
  // SPEC §12: the cell's 4×4 matrix is the projective map of space fixed by five point pairs —
  // three of the rectangle's corner rays at depth znear, the fourth at zfar, and the centre's at
  // depth 10 — sent to their clip positions (glFrustum's depth: z/w = (f + n)/(f − n) −
  // 2fn/((f − n)·depth)).
  const CylinderRig rig = threeProjectorCylinder(3, 10, 320, 200);
  const DirectionTable t = directionTable(rig.geometry(0));
  const SubFrustumOptions o;
  const SubFrustumPlan plan = planSubFrusta(t, o);
  for (size_t k : {size_t(0), plan.cells.size() / 2, plan.cells.size() - 1}) {
    const SubFrustumCell& c = plan.cells[k];
    const Vec3d axis{c.map.m[2][0], c.map.m[2][1], c.map.m[2][2]};
    auto at = [&](double px, double py, double depth) {
      const Vec3d d = mapPixel(c, px, py);
      const Vec3d p = d * (depth / dot(d, axis));
      return Vec4d{{p.x, p.y, p.z, 1}};
    };
    const double n = o.znear, f = o.zfar, depth = 10;
    const double zMid = (f + n) / (f - n) - 2 * f * n / ((f - n) * depth);
    const std::array<Vec4d, 5> M = {at(c.x0, c.y0, n), at(c.x1, c.y0, n), at(c.x0, c.y1, n),
                                    at(c.x1, c.y1, f),
                                    at(0.5 * (c.x0 + c.x1), 0.5 * (c.y0 + c.y1), depth)};
    const std::array<Vec4d, 5> P = {Vec4d{{-1, 1, -1, 1}}, Vec4d{{1, 1, -1, 1}},
                                    Vec4d{{-1, -1, -1, 1}}, Vec4d{{1, -1, 1, 1}},
                                    Vec4d{{0, 0, zMid, 1}}};
    const Result<Mat4d> five = solveProjectiveMap(M, P);
    ASSERT_TRUE(five.ok()) << five.error().str();
    // Equal up to scale: compare both divided by their (3, 2) entry, the axis's z.
    double diff = 0, scale = 0;
    const double sa = five.value().m[3][2], sb = c.projection.m[3][2];
    for (int r = 0; r < 4; ++r)
      for (int q = 0; q < 4; ++q) {
        diff = std::max(diff, std::fabs(five.value().m[size_t(r)][size_t(q)] / sa -
                                        c.projection.m[size_t(r)][size_t(q)] / sb));
        scale = std::max(scale, std::fabs(c.projection.m[size_t(r)][size_t(q)] / sb));
      }
    EXPECT_LT(diff / scale, 1e-8) << "cell " << k;
  }
}

TEST(SubFrustum, EachCellsFrustumCoversItsPixels) {
  const CylinderRig rig = threeProjectorCylinder(3, 10, 320, 200);
  const DirectionTable t = directionTable(rig.geometry(1));
  const SubFrustumPlan plan = planSubFrusta(t);
  for (const SubFrustumCell& c : plan.cells) {
    const CellFrustum f = cellFrustum(c);
    // The frustum as a one-pixel flat view: every direction of the cell lands in [0, 1]².
    const FlatView v{f.orientation, f.window, 1, 1};
    for (int y = c.y0; y < c.y1; ++y)
      for (int x = c.x0; x < c.x1; ++x) {
        const Vec3d d = t.directions[t.index(x, y)];
        const std::optional<FlatPoint> p = flatPointOf(v, Vec3{float(d.x), float(d.y), float(d.z)});
        ASSERT_TRUE(p);
        EXPECT_TRUE(p->x >= 0 && p->x <= 1 && p->y >= 0 && p->y <= 1)
            << "cell " << c.x0 << "," << c.y0 << " pixel " << x << "," << y << ": " << p->x << ", "
            << p->y;
      }
    // And it is tight: the window is within a pixel or so of the cell's angular size.
    const double width = (f.window.rightDegrees - f.window.leftDegrees) * kToRadians;
    EXPECT_LT(width, 0.02 * (c.x1 - c.x0 + 2));
  }
}

TEST(SubFrustum, OrientationOfInvertsRotationOf) {
  for (const Orientation o : {Orientation{0, 0, 0}, Orientation{37, -12, 8},
                              Orientation{-150, 60, -170}, Orientation{91, -89, 45}}) {
    const Orientation back = orientationOf(rotationOf(o));
    const Rotation a = rotationOf(o), b = rotationOf(back);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(a.m[r][c], b.m[r][c], 1e-12);
  }
}

TEST(SubFrustum, PartlyInvalidDisplayKeepsOnlyCellsWithValidPixels) {
  // The centre projector on a screen cut to ±24° of azimuth and 0.8 m above the eye: its image's
  // sides and top miss the screen.
  CylinderRig rig = threeProjectorCylinder(3, 10, 320, 200);
  rig.screen.minAzimuthDegrees = -24;
  rig.screen.maxAzimuthDegrees = 24;
  rig.screen.maxHeight = 0.8;
  const DirectionTable t = directionTable(rig.geometry(1));
  int64_t invalid = 0;
  for (uint8_t v : t.valid) invalid += !v;
  ASSERT_GT(invalid, 0);
  const SubFrustumPlan plan = planSubFrusta(t);
  expectTiling(plan, t);
  EXPECT_EQ(plan.cellsAboveBound, 0);
  EXPECT_EQ(plan.unfittedPixels, 0);
  int partly = 0;
  for (const SubFrustumCell& c : plan.cells)
    partly += c.validPixels < int64_t(c.x1 - c.x0) * (c.y1 - c.y0);
  EXPECT_GT(partly, 0);
  std::printf(
      "partly invalid 320 x 200 (%lld invalid pixels): %zu cells, %d partly valid, max "
      "residual %.4f px\n",
      static_cast<long long>(invalid), plan.cells.size(), partly, plan.maxResidualPixels);
}

TEST(SubFrustum, MovingTheEyeChangesTheMapsAndThePlanIsRecomputed) {
  // Dynamic correction (SPEC §12: unit vectors recomputed per frame for a moving eye): a
  // 1920 × 1080 projector of the rig, the eye at the centre and then moved by a head's motion.
  CylinderRig rig = threeProjectorCylinder(3, 10, 1920, 1080);
  auto t0 = std::chrono::steady_clock::now();
  const DirectionTable still = directionTable(rig.geometry(0));
  const double tableMs = millisecondsSince(t0);
  t0 = std::chrono::steady_clock::now();
  const SubFrustumPlan before = planSubFrusta(still);
  const double planMs = millisecondsSince(t0);
  rig.eye = {0.15f, 0.05f, -0.1f};
  t0 = std::chrono::steady_clock::now();
  const DirectionTable moved = directionTable(rig.geometry(0));
  const SubFrustumPlan after = planSubFrusta(moved);
  const double movedMs = millisecondsSince(t0);
  EXPECT_EQ(before.cellsAboveBound, 0);
  EXPECT_EQ(after.cellsAboveBound, 0);
  expectTiling(after, moved);
  // The old maps no longer fit: the eye's move shifts what each pixel should show by many pixels.
  double stale = 0;
  for (const SubFrustumCell& c : before.cells)
    for (int y = c.y0; y < c.y1; y += 7)
      for (int x = c.x0; x < c.x1; x += 7) {
        const std::optional<PixelPoint> p = mapDirection(c, moved.directions[moved.index(x, y)]);
        stale = std::max(stale, p ? std::hypot(p->x - (x + 0.5), p->y - (y + 0.5)) : 1e9);
      }
  EXPECT_GT(stale, 10);
  std::printf(
      "1920 x 1080 projector: directions %.1f ms, plan %.1f ms (%zu cells, max %.4f px); "
      "eye moved: directions + plan %.1f ms (%zu cells, max %.4f px); the old maps miss "
      "by up to %.1f px\n",
      tableMs, planMs, before.cells.size(), before.maxResidualPixels, movedMs, after.cells.size(),
      after.maxResidualPixels, stale);
}

// Issue 61 item 2: for a moved eye the cells stay and their maps are refitted on their kept screen
// points (refitPlan) — every valid pixel then within the bound by brute force through the cells'
// projections against the new eye's exact directions, as a plan made from scratch for that eye;
// a head's small move refits every cell, a large one plans a few again.
TEST(SubFrustum, AMovedEyeRefitsTheMapsOfTheSameCellsWithinTheBound) {
  CylinderRig rig = threeProjectorCylinder(3, 10, 640, 400);
  const DirectionTable still = directionTable(rig.geometry(0));
  const SubFrustumPlan plan = planSubFrusta(still);
  const PlanScreenPoints points = planScreenPoints(plan, still, rig.geometry(0));
  ASSERT_EQ(points.first.size(), plan.cells.size() + 1);
  for (const Vec3 eye : {Vec3{0.02f, 0.01f, -0.01f}, Vec3{0.15f, 0.05f, -0.1f}}) {
    rig.eye = eye;
    const DisplayGeometry g = rig.geometry(0);
    RefitStats stats;
    const auto t0 = std::chrono::steady_clock::now();
    const SubFrustumPlan refit = refitPlan(plan, points, g, {}, &stats);
    const double refitMs = millisecondsSince(t0);
    // On threads: the same plan.
    core::ThreadPool pool(3);
    const SubFrustumPlan threaded = refitPlan(plan, points, g, {}, nullptr, &pool);
    ASSERT_EQ(threaded.cells.size(), refit.cells.size());
    for (size_t i = 0; i < refit.cells.size(); ++i) {
      EXPECT_EQ(threaded.cells[i].x0, refit.cells[i].x0);
      EXPECT_EQ(threaded.cells[i].y1, refit.cells[i].y1);
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k)
          EXPECT_EQ(threaded.cells[i].map.m[r][k], refit.cells[i].map.m[r][k]);
    }
    const DirectionTable moved = directionTable(g);
    expectTiling(refit, moved);
    double worst = 0;
    for (const SubFrustumCell& c : refit.cells)
      if (c.fitted) worst = std::max(worst, bruteForce(c, moved).pixels);
    const SubFrustumPlan scratch = planSubFrusta(moved);
    SCOPED_TRACE(testing::Message() << "eye " << eye.x << ", " << eye.y << ", " << eye.z);
    EXPECT_LE(worst, 0.1);
    EXPECT_LE(scratch.maxResidualPixels, 0.1);
    EXPECT_EQ(stats.refitted + stats.replanned, int(plan.cells.size()));
    if (eye.x < 0.05f) {
      EXPECT_EQ(stats.replanned, 0) << "a head's small move refits every cell";
      EXPECT_EQ(refit.cells.size(), plan.cells.size());
    }
    std::printf(
        "640 x 400, eye moved to (%.2f, %.2f, %.2f): refit %.2f ms (%d cells refitted, %d planned "
        "again; %zu cells, brute-force max %.4f px); from scratch %zu cells, max %.4f px\n",
        eye.x, eye.y, eye.z, refitMs, stats.refitted, stats.replanned, refit.cells.size(), worst,
        scratch.cells.size(), scratch.maxResidualPixels);
  }
}

}  // namespace
}  // namespace sv::display
