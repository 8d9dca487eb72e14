// The pyramid's bounds and the caster's hits against brute force (issue 29's acceptance).
#include "terrain/caster.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "formats/heights.h"
#include "terrain/dense_march.h"

namespace sv::terrain {
namespace {

using tests::denseMarch;

// Tables to cast over, made as the formats make them.
using formats::generateFractal;
using formats::quantize;

const Interpolation kFilters[] = {Interpolation::bilinear, Interpolation::bicubic};

TEST(Pyramid, EveryBoundHoldsEveryInterpolatedSampleOfItsNodes) {
  const HeightField f = generateFractal(77, 10, 800, 5).value();  // odd size: padded nodes
  for (Interpolation interp : kFilters) {
    const Pyramid p(f, interp);
    const int n = p.gridLevel();
    ASSERT_EQ(p.cellsX(), 76);
    ASSERT_EQ(n, 7);
    // Level n (cells, computed) and every stored level: 6×6 samples a cell, edges included.
    for (int level = 0; level <= n; ++level) {
      const int cells = p.nodeCells(level);
      for (int j = 0; j * cells < p.cellsY(); ++j)
        for (int i = 0; i * cells < p.cellsX(); ++i) {
          const Pyramid::Range r = p.node(level, i, j);
          ASSERT_LE(r.lo, r.hi);
          const int step = std::max(1, cells / 4);  // coarse levels: every fourth cell
          for (int cy = j * cells; cy < std::min((j + 1) * cells, p.cellsY()); cy += step)
            for (int cx = i * cells; cx < std::min((i + 1) * cells, p.cellsX()); cx += step)
              for (int sy = 0; sy <= 5; ++sy)
                for (int sx = 0; sx <= 5; ++sx) {
                  const double h = interpolate(f, interp, cx + sx / 5.0, cy + sy / 5.0);
                  ASSERT_GE(h, r.lo - 1e-9) << interpolationName(interp) << " level " << level;
                  ASSERT_LE(h, r.hi + 1e-9) << interpolationName(interp) << " level " << level;
                }
        }
    }
  }
}

TEST(Pyramid, BicubicBoundsIncludeTheOvershoot) {
  // A step: Catmull–Rom rings below 0 and above 1 next to it.
  std::vector<double> v(8 * 8);
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 8; ++i) v[size_t(j * 8 + i)] = i < 4 ? 0.0 : 100.0;
  const HeightField f = quantize(v, 8, 8, "step").value();
  const double low = interpolate(f, Interpolation::bicubic, 2.5, 3);
  EXPECT_LT(low, 0.0);  // the overshoot is real
  const Pyramid p(f, Interpolation::bicubic);
  EXPECT_LE(p.node(p.gridLevel(), 2, 3).lo, low);
  EXPECT_LE(p.node(0, 0, 0).lo, low);
}

void castAgainstDenseMarch(double radius) {
  const HeightField f = generateFractal(129, 20, 600, 9).value();
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0, 1);
  for (Interpolation interp : kFilters) {
    const Pyramid p(f, interp);
    const Caster c(f, p, interp, Placement{0, 0, radius});
    int hits = 0, grazing = 0;
    for (int k = 0; k < 300; ++k) {
      // From 5 … 700 m above the base somewhere over (or beside) the map, looking down 0.2° …
      // 40°: grazing rays included.
      const double half = 64 * 20.0 * 1.2;
      const Vec3d o{(2 * u(rng) - 1) * half, 5 + 700 * u(rng), (2 * u(rng) - 1) * half};
      const double yaw = 2 * M_PI * u(rng), pitch = -(0.2 + 40 * u(rng) * u(rng)) * M_PI / 180;
      const Vec3d d{std::cos(pitch) * std::cos(yaw), std::sin(pitch),
                    std::cos(pitch) * std::sin(yaw)};
      CastCounters counters;
      const double s1 = 4000;
      const double got = c.cast(o, d, 0, s1, counters);
      const double want = denseMarch(c, o, d, 0, s1);
      if (std::fabs(pitch) < 2 * M_PI / 180) ++grazing;
      ASSERT_EQ(std::isnan(got), std::isnan(want))
          << interpolationName(interp) << " ray " << k << " got " << got << " want " << want;
      if (std::isnan(got)) continue;
      ++hits;
      // Tolerance: 10⁻³ of a grid step along the ray (the march finds the same crossing).
      ASSERT_NEAR(got, want, 2e-3 * 20) << interpolationName(interp) << " ray " << k;
    }
    EXPECT_GT(hits, 100);
    EXPECT_GT(grazing, 10);
  }
}

TEST(Caster, HitsAgreeWithADenseMarchOnThePlane) { castAgainstDenseMarch(0); }
TEST(Caster, HitsAgreeWithADenseMarchOnASphere) { castAgainstDenseMarch(50000); }

TEST(Caster, MapAndWorldAreInverse) {
  const HeightField f = generateFractal(33, 100, 600, 9).value();
  const Pyramid p(f, Interpolation::bilinear);
  for (double radius : {0.0, 6371000.0}) {
    const Caster c(f, p, Interpolation::bilinear, Placement{150, -320, radius});
    for (double gx : {0.0, 7.5, 32.0})
      for (double gy : {0.0, 13.25, 32.0}) {
        const Caster::MapPoint m = c.toMap(c.toWorld(gx, gy, 123.0));
        EXPECT_NEAR(m.gx, gx, 1e-6);
        EXPECT_NEAR(m.gy, gy, 1e-6);
        EXPECT_NEAR(m.h, 123.0, 1e-6);
      }
  }
}

TEST(Caster, TheSideOfThePrismIsAWall) {
  // A flat table 100 m high: a level ray at 50 m from outside meets its western edge.
  const HeightField f = quantize(std::vector<double>(16 * 16, 100.0), 16, 16, "flat").value();
  const Pyramid p(f, Interpolation::bilinear);
  const Caster c(f, p, Interpolation::bilinear, Placement{7.5, -7.5, 0});
  CastCounters counters;
  const double s = c.cast({-20, 50, 0}, {1, 0, 0}, 0, 100, counters);
  EXPECT_NEAR(s, 20 - 7.5, 1e-5);
  EXPECT_TRUE(std::isnan(c.cast({-20, 150, 0}, {1, 0, 0}, 0, 100, counters)));
}

TEST(Caster, ABicubicPeakBetweenSamplesIsMetBelowItsTopAndMissedAbove) {
  // Four high samples in a flat table: the Catmull–Rom surface overshoots them between the four,
  // inside a cell. Level rays that pass a third of the overshoot below that peak meet it, a third
  // of a code above miss it — a cell passed on the samples' range alone (without the overshoot)
  // would miss the first. (A ray that grazes the peak by less than the surface falls over an
  // eighth of a cell may miss it: caster.h.)
  HeightField f;
  f.width = f.height = 33;
  f.spacingU = f.spacingV = 10;
  f.originV = 320;
  f.scale = 0.01;
  f.q.assign(size_t(f.width) * size_t(f.height), 1000);
  for (int j = 15; j <= 16; ++j)
    for (int i = 15; i <= 16; ++i) f.q[size_t(j) * size_t(f.width) + size_t(i)] = 10000;
  const Pyramid p(f, Interpolation::bicubic);
  const Caster c(f, p, Interpolation::bicubic, Placement{});
  // The peak: at the cell's centre by symmetry.
  const double peak = c.surface(15.5, 15.5);
  ASSERT_GT(peak, 10000 * f.scale + 5);  // overshoot of metres, not rounding
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 2 * M_PI);
  for (const double margin : {-(peak - 10000 * f.scale) / 3, 0.3 * f.scale})
    for (int k = 0; k < 32; ++k) {
      const double heading = u(rng);
      const Vec3d d{std::cos(heading), 0, std::sin(heading)};
      const Vec3d o = c.toWorld(15.5, 15.5, peak + margin) - d * 150.0;
      CastCounters counters;
      const double hit = c.cast(o, d, 0, 300, counters);
      if (margin < 0) {
        ASSERT_FALSE(std::isnan(hit)) << "heading " << heading;
        EXPECT_LE(hit, 150 + 1e-3);
      } else {
        EXPECT_TRUE(std::isnan(hit)) << "heading " << heading;
      }
    }
}

}  // namespace
}  // namespace sv::terrain
