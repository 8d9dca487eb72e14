// Multi-level ray casting (SPEC §12): hits against analytic ray–quadric intersections for every
// quadric kind — silhouettes (grazing rays) and a sphere cut by the near plane included — masking
// on and off giving identical buffers, the fixed-step marcher agreeing with the caster, and the
// SIMD solver of monotonic windows against analytic roots on every target.
#include "freeform/raycast.h"

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "every_target.h"
#include "freeform/tessellate.h"

namespace sv::freeform {
namespace {

constexpr double kFovY = 60 * M_PI / 180, kNear = 1, kFar = 10;

// Projection · view for a camera at (0, 0, 4) looking down −z (OpenGL conventions, as the
// renderer's): object space → the cube.
Mat4d cameraToCube(int width, int height) {
  const double f = 1 / std::tan(kFovY / 2), aspect = double(width) / height;
  Mat4d p;
  p.m = {{{f / aspect, 0, 0, 0},
          {0, f, 0, 0},
          {0, 0, (kFar + kNear) / (kNear - kFar), 2 * kFar * kNear / (kNear - kFar)},
          {0, 0, -1, 0}}};
  Mat4d v;
  v.m[2][3] = -4;
  return p * v;
}

struct Buffers {
  int width, height;
  std::vector<float> depth;
  std::vector<double> cubeZ;
  std::vector<uint32_t> object;
  Buffers(int w, int h)
      : width(w),
        height(h),
        depth(size_t(w) * h, 1.0f),
        cubeZ(size_t(w) * h, 0),
        object(size_t(w) * h, kNoHit) {}
};

// The 64×64 window of `b` at (x0, y0).
CastWindow windowOf(Buffers& b, int x0, int y0) {
  CastWindow w;
  w.width = b.width;
  w.height = b.height;
  w.x0 = x0;
  w.y0 = y0;
  w.size = 64;
  const size_t at = size_t(y0) * size_t(b.width) + size_t(x0);
  w.depth = b.depth.data() + at;
  w.cubeZ = b.cubeZ.data() + at;
  w.object = b.object.data() + at;
  w.stride = b.width;
  return w;
}

// Casts `form` over the whole raster in 64×64 windows (or marches it, steps > 0).
CastStats cast(const ProjectedFreeForm& form, uint32_t id, Buffers& b, bool masking = true,
               int steps = 0) {
  CastStats stats;
  for (int y0 = 0; y0 < b.height; y0 += 64)
    for (int x0 = 0; x0 < b.width; x0 += 64) {
      const CastWindow w = windowOf(b, x0, y0);
      if (steps > 0)
        marchWindow(form, id, w, steps, stats);
      else
        castWindow(form, id, w, CastSettings{masking}, stats);
    }
  return stats;
}

// The first zero of the plain quadric q along pixel (px, py)'s ray between the near and far
// planes, solved as a quadratic in object space; false if the ray misses.
bool analyticHit(const Quadric& q, const ProjectedFreeForm& g, int px, int py, int w, int h,
                 Vec3d& hit) {
  const double x = 2.0 * (px + 0.5) / w - 1, y = 1 - 2.0 * (py + 0.5) / h;
  const Vec3d o = g.toObject({x, y, -1}), d = g.toObject({x, y, 1}) - o;
  // F(o + s·d) = a·s² + b·s + c, its coefficients from three evaluations (exact for a quadric).
  const double c = q.evaluate(o), fp = q.evaluate(o + d), fm = q.evaluate(o - d);
  const double a = 0.5 * (fp + fm) - c, b = 0.5 * (fp - fm);
  std::vector<double> roots;
  if (std::fabs(a) < 1e-14) {
    if (b != 0) roots.push_back(-c / b);
  } else {
    const double disc = b * b - 4 * a * c;
    if (disc <= 0) return false;  // a miss, or a tangent touch: no crossing
    const double r = std::sqrt(disc);
    // Stable form of the two roots.
    const double t = -0.5 * (b + std::copysign(r, b));
    roots = {t / a, c / t};
  }
  double best = 2;
  for (double s : roots)
    if (s >= 0 && s <= 1) best = std::min(best, s);
  if (best > 1) return false;
  hit = o + d * best;
  return true;
}

struct Shape {
  const char* name;
  Quadric q;
};

TEST(RayCast, HitsMatchAnalyticRayQuadricIntersectionsForEveryKind) {
  const int w = 96, h = 64;
  const Mat4d toCube = cameraToCube(w, h);
  const Shape shapes[] = {
      {"sphere", Quadric::sphere({0.2, -0.1, 0}, 1)},
      {"ellipsoid", Quadric::ellipsoid({0, 0, 0.5}, {1.5, 0.5, 0.8})},
      {"cylinder", Quadric::cylinder({0.3, 0, 0}, {0.2, 1, 0.1}, 0.5)},
      {"cone", Quadric::cone({0, 0.5, 0}, {0, 1, 0.3}, 0.4)},
      {"paraboloid", Quadric::paraboloid({0, -0.8, 0}, {0, 1, 0}, 1.5)},
      {"plane", Quadric::halfSpace({0, 1, 0.2}, -0.5)},
      {"sphere cut by the near plane", Quadric::sphere({0.3, 0, 2.6}, 0.8)},
  };
  const double pixel = 2 * std::tan(kFovY / 2) / h;  // pixel footprint per unit of distance
  for (const Shape& s : shapes) {
    FreeForm f;
    f.base = s.q;
    const std::optional<ProjectedFreeForm> g = ProjectedFreeForm::make(f, toCube);
    ASSERT_TRUE(g);
    Buffers b(w, h);
    cast(*g, 7, b);
    int hits = 0, mismatched = 0;
    double worst = 0;
    for (int py = 0; py < h; ++py)
      for (int px = 0; px < w; ++px) {
        Vec3d expected;
        const bool analytic = analyticHit(s.q, *g, px, py, w, h, expected);
        const size_t at = size_t(py) * w + size_t(px);
        const bool cast = b.object[at] == 7;
        if (analytic != cast) {
          ++mismatched;
          continue;
        }
        if (!cast) continue;
        ++hits;
        const double x = 2.0 * (px + 0.5) / w - 1, y = 1 - 2.0 * (py + 0.5) / h;
        const Vec3d got = g->toObject({x, y, b.cubeZ[at]});
        const Vec3d eye{0, 0, 4};
        const double cell = pixel * std::sqrt(dot(expected - eye, expected - eye));
        const Vec3d e = got - expected;
        worst = std::max(worst, std::sqrt(dot(e, e)) / cell);
      }
    EXPECT_GT(hits, 200) << s.name;
    // Only rays grazing the silhouette within the bracket width may disagree.
    EXPECT_LE(mismatched, 2) << s.name;
    EXPECT_LE(worst, 1e-3) << s.name << ": error in cells";
  }
}

// A unit sphere with six bumps around it, toward the camera.
FreeForm sculpture() {
  FreeForm f;
  f.base = Quadric::sphere({0, 0, 0}, 1);
  for (int i = 0; i < 6; ++i) {
    const double a = i * M_PI / 3;
    FreeForm bump;
    bump.base = Quadric::sphere({0.9 * std::cos(a), 0.9 * std::sin(a), 0.3}, 0.45);
    f.perturbations.push_back(bump);
  }
  return f;
}

// A sphere with a bump, so that a ray's bound has a perturbation's terms.
FreeForm bumpedSphere() {
  FreeForm f;
  f.base = Quadric::sphere({0.2, -0.1, 0}, 1.2);
  FreeForm bump;
  bump.base = Quadric::sphere({0.2, -0.1, 1.2}, 0.4);
  f.perturbations.push_back(bump);
  return f;
}

// The truth for a ray (x, y) of g: the first sign change of H in [from, zhi], by fine steps and
// bisection; NaN if none.
double firstSignChange(const ProjectedFreeForm& g, double x, double y, double zhi,
                       double from = -1) {
  RayFunction ray;
  g.ray(x, y, ray);
  double a = from, fa = ray.evaluate(a);
  for (int k = 1; k <= 4096; ++k) {
    const double b = std::min(zhi, from + (1 - from) * k / 4096), fb = ray.evaluate(b);
    if ((fa >= 0) != (fb >= 0)) {
      double lo = a, hi = b;
      for (int it = 0; it < 80; ++it) {
        const double m = 0.5 * (lo + hi);
        ((ray.evaluate(m) >= 0) == (fa >= 0) ? lo : hi) = m;
      }
      return lo;
    }
    if (b >= zhi) break;
    a = b, fa = fb;
  }
  return NAN;
}

// ProjectedFreeForm::monotonicCrossings: rays into a sphere, each over the span from the near
// plane to the middle of its chord (one zero: the entry), give the analytic entry; rays that miss,
// over the whole depth, give NaN; so do empty spans. Any count of rays, any guess, and the same
// bits on every compiled target.
TEST(RayCast, MonotonicCrossingsAreTheEntriesOnEveryTarget) {
  const int w = 64, h = 64;
  const Quadric sphere = Quadric::sphere({0.2, -0.1, 0}, 1.2);
  FreeForm f;
  f.base = sphere;
  const Mat4d toCube = cameraToCube(w, h);
  const auto g = ProjectedFreeForm::make(f, toCube);
  ASSERT_TRUE(g);
  std::mt19937 rng(8);
  std::uniform_int_distribution<int> pixel(0, w - 1);
  onEveryTarget([&](int64_t target, std::vector<double>& results) {
    rng.seed(8);
    int entries = 0, misses = 0;
    for (int round = 0; round < 200; ++round) {
      const int count = 1 + round % 16;
      double x[16], y[16], zhi[16], z[16], expected[16];
      for (int i = 0; i < count; ++i) {
        const int px = pixel(rng), py = pixel(rng);
        x[i] = 2.0 * (px + 0.5) / w - 1;
        y[i] = 1 - 2.0 * (py + 0.5) / h;
        const Vec3d o = g->toObject({x[i], y[i], -1}), d = g->toObject({x[i], y[i], 1}) - o;
        const double c = sphere.evaluate(o), fp = sphere.evaluate(o + d),
                     fm = sphere.evaluate(o - d);
        const double a = 0.5 * (fp + fm) - c, b = 0.5 * (fp - fm), disc = b * b - 4 * a * c;
        if (disc > 0) {  // F = a·s² + b·s + c, a < 0: entry and exit
          const double s0 = (-b + std::sqrt(disc)) / (2 * a), s1 = (-b - std::sqrt(disc)) / (2 * a);
          expected[i] = toCube.transformPoint(o + d * std::min(s0, s1)).z;
          zhi[i] = toCube.transformPoint(o + d * (0.5 * (s0 + s1))).z;
          if (i % 5 == 4) zhi[i] = -1, expected[i] = NAN;  // an empty span
        } else {
          zhi[i] = 1;
          expected[i] = NAN;
        }
      }
      // Guesses: none, a near one (another ray's entry), a wild one — mixed across the lanes.
      double guess[16];
      for (int i = 0; i < count; ++i)
        guess[i] = (round + i) % 3 == 0 ? NAN : (round + i) % 3 == 1 ? expected[0] : 0.9;
      g->monotonicCrossings(x, y, -1, zhi, count, guess, z);
      for (int i = 0; i < count; ++i) {
        results.push_back(z[i]);
        if (std::isnan(expected[i])) {
          EXPECT_TRUE(std::isnan(z[i]))
              << hwy::TargetName(target) << " round " << round << " ray " << i;
          ++misses;
        } else {
          EXPECT_NEAR(z[i], expected[i], 1e-9)
              << hwy::TargetName(target) << " round " << round << " ray " << i;
          ++entries;
        }
      }
    }
    EXPECT_GT(entries, 300);
    EXPECT_GT(misses, 200);
  });
}

// ProjectedFreeForm::piecewiseCrossings: rays into a sphere over the whole depth (entry and exit,
// so H turns along them) give the analytic entry — found in a monotonic piece, or by the ray's own
// subdivision (castRay) from where the lane handed it over; rays that miss give nothing. The
// same bits on every compiled target, and both ways of finding a hit taken.
TEST(RayCast, PiecewiseCrossingsAreTheEntriesOnEveryTarget) {
  const int w = 64, h = 64;
  const auto g = ProjectedFreeForm::make(bumpedSphere(), cameraToCube(w, h));
  ASSERT_TRUE(g);
  onEveryTarget([&](int64_t target, std::vector<double>& results) {
    std::mt19937 rng(10);
    std::uniform_int_distribution<int> pixel(0, w - 1);
    int inLanes = 0, handedOver = 0, misses = 0;
    for (int round = 0; round < 200; ++round) {
      const int count = 1 + round % 16;
      double x[16], y[16], zhi[16], z[16], from[16];
      for (int i = 0; i < count; ++i) {
        x[i] = 2.0 * (pixel(rng) + 0.5) / w - 1;
        y[i] = 1 - 2.0 * (pixel(rng) + 0.5) / h;
        zhi[i] = i % 7 == 6 ? -0.5 : 1;  // some spans end early
      }
      const double none[16] = {NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN,
                               NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN};
      g->piecewiseCrossings(x, y, -1, zhi, count, 8, none, z, from);
      for (int i = 0; i < count; ++i) {
        double hit = z[i];
        if (!std::isnan(z[i])) {
          ++inLanes;
        } else if (!std::isnan(from[i])) {
          ++handedOver;
          float depth = float(0.5 * (zhi[i] + 1));
          uint32_t object = kNoHit;
          RayFunction ray;
          CastStats stats;
          castRay(*g, 1, x[i], y[i], from[i], NAN, depth, object, hit, ray, stats);
          if (object == kNoHit) hit = NAN;
        }
        const double want = firstSignChange(*g, x[i], y[i], zhi[i]);
        if (std::isnan(want)) {
          EXPECT_TRUE(std::isnan(hit))
              << hwy::TargetName(target) << " round " << round << " ray " << i;
          ++misses;
        } else {
          EXPECT_NEAR(hit, want, 1e-9)
              << hwy::TargetName(target) << " round " << round << " ray " << i;
        }
        results.push_back(z[i]);
        results.push_back(from[i]);
      }
    }
    EXPECT_GT(inLanes, 100);
    EXPECT_GT(handedOver, 20);
    EXPECT_GT(misses, 200);
  });
}

// ProjectedFreeForm::crossingBracket: rays into a bumped sphere from spans starting in front of
// it or partway in (H turns along them) get a bracket of their first sign change — H of opposite
// signs at its ends — or none where they have none; a budget of one split decides some of them
// and not others. The same bits on every compiled target.
TEST(RayCast, CrossingBracketsHoldTheFirstSignChangeOnEveryTarget) {
  const int w = 64, h = 64;
  const auto g = ProjectedFreeForm::make(bumpedSphere(), cameraToCube(w, h));
  ASSERT_TRUE(g);
  onEveryTarget([&](int64_t target, std::vector<double>& results) {
    std::mt19937 rng(18);
    std::uniform_int_distribution<int> pixel(0, w - 1);
    std::uniform_real_distribution<double> depth(-1, 0.5);
    int found = 0, misses = 0, disagree = 0, cutShort = 0;
    for (int round = 0; round < 1500; ++round) {
      const double x = 2.0 * (pixel(rng) + 0.5) / w - 1, y = 1 - 2.0 * (pixel(rng) + 0.5) / h;
      const double zlo = round % 2 == 0 ? -1 : depth(rng), zhi = round % 3 == 0 ? 0.6 : 1;
      const double want = firstSignChange(*g, x, y, zhi, zlo);
      double bracket[4] = {NAN, NAN, NAN, NAN};
      int bounds = 0;
      const bool got =
          g->crossingBracket(x, y, zlo, zhi, kAllActive, 0x1p-16, 256, bracket, bounds);
      EXPECT_EQ(bounds % 8, 0);
      results.insert(results.end(), bracket, bracket + 4);
      if (got != !std::isnan(want)) {
        ++disagree;  // only a ray grazing the surface within the truth's step may
        continue;
      }
      if (!got) {
        ++misses;
        continue;
      }
      ++found;
      const std::string where =
          std::string(hwy::TargetName(target)) + " round " + std::to_string(round);
      EXPECT_LE(bracket[0], want + 1e-12) << where;
      EXPECT_GE(bracket[1], want - 1e-12) << where;
      EXPECT_NE(bracket[2] >= 0, bracket[3] >= 0) << where;
      int few = 0;
      if (!g->crossingBracket(x, y, zlo, zhi, kAllActive, 0x1p-16, 1, bracket, few)) ++cutShort;
    }
    EXPECT_LE(disagree, 3);
    EXPECT_GT(found, 300);
    EXPECT_GT(misses, 300);
    EXPECT_GT(cutShort, 50);     // crossings a first split leaves undecided
    EXPECT_LT(cutShort, found);  // and those it decides
  });
}

// ProjectedFreeForm::provenCrossings: rays into a bumped sphere over the whole depth (H turns
// along them), Newton from a guess near the entry (a neighbour's hit), at the exit (a zero that
// is not the first), far off or none: every zero it keeps is the ray's first crossing (so never
// an exit); most of those guessed near the entry are kept. The same bits on every compiled
// target.
TEST(RayCast, ProvenCrossingsAreOnlyFirstCrossingsOnEveryTarget) {
  const int w = 64, h = 64;
  const auto g = ProjectedFreeForm::make(bumpedSphere(), cameraToCube(w, h));
  ASSERT_TRUE(g);
  onEveryTarget([&](int64_t target, std::vector<double>& results) {
    std::mt19937 rng(12);
    std::uniform_int_distribution<int> pixel(0, w - 1);
    std::uniform_real_distribution<double> jitter(-1e-4, 1e-4);
    int nearKept = 0, nearTried = 0, exitsTried = 0;
    for (int round = 0; round < 400; ++round) {
      const int count = 1 + round % 16;
      double x[16], y[16], zhi[16], z[16], guess[16], want[16];
      int kind[16];
      for (int i = 0; i < count; ++i) {
        x[i] = 2.0 * (pixel(rng) + 0.5) / w - 1;
        y[i] = 1 - 2.0 * (pixel(rng) + 0.5) / h;
        zhi[i] = 1;
        want[i] = firstSignChange(*g, x[i], y[i], zhi[i]);
        // The exit: the next sign change beyond the entry.
        const double exit =
            std::isnan(want[i]) ? NAN : firstSignChange(*g, x[i], y[i], zhi[i], want[i] + 1e-6);
        kind[i] = (round + i) % 4;
        guess[i] = kind[i] == 0   ? want[i] + jitter(rng)
                   : kind[i] == 1 ? exit
                   : kind[i] == 2 ? NAN
                                  : 0.95;
        if (kind[i] == 1 && !std::isnan(exit)) ++exitsTried;
      }
      g->provenCrossings(x, y, -1, zhi, count, guess, z);
      for (int i = 0; i < count; ++i) {
        results.push_back(z[i]);
        if (std::isnan(z[i])) continue;
        ASSERT_FALSE(std::isnan(want[i]))
            << hwy::TargetName(target) << " round " << round << " ray " << i << " kept a zero";
        EXPECT_NEAR(z[i], want[i], 1e-9)
            << hwy::TargetName(target) << " round " << round << " ray " << i;
      }
      for (int i = 0; i < count; ++i)
        if (kind[i] == 0 && !std::isnan(want[i])) {
          ++nearTried;
          nearKept += std::isnan(z[i]) ? 0 : 1;
        }
    }
    EXPECT_GT(nearTried, 150);
    EXPECT_GT(exitsTried, 150);
    EXPECT_GT(nearKept, nearTried * 3 / 4) << nearKept << " of " << nearTried;
  });
}

// A cylinder capped at both ends (a quadric and two clips), tilted toward the camera.
FreeForm cappedCylinder() {
  const Vec3d axis{0.3, 0.5, 0.8};
  FreeForm f;
  f.base = Quadric::cylinder({0, 0, 0}, axis, 1.1);
  f.clips = {Quadric::halfSpace(axis, 1.3), Quadric::halfSpace(axis * -1.0, 1.3)};
  return f;
}

// ProjectedFreeForm::quadricCrossings: up to 64 rays of a capped cylinder (a quadric and two clips)
// over spans from the near plane or from a depth partway in — so starting in front of it, inside it
// or past it — give the first sign change of H: entries through the side and through a cap, exits
// where the span starts inside, nothing for misses and empty spans. The same bits on every
// compiled target.
TEST(RayCast, QuadricCrossingsAreTheFirstSignChangesOnEveryTarget) {
  const int w = 64, h = 64;
  const FreeForm f = cappedCylinder();
  const auto g = ProjectedFreeForm::make(f, cameraToCube(w, h));
  ASSERT_TRUE(g);
  EXPECT_TRUE(g->quadricsAlone(0));
  EXPECT_TRUE(g->quadricsAlone(kAllActive));  // no perturbations at all
  onEveryTarget([&](int64_t target, std::vector<double>& results) {
    std::mt19937 rng(14);
    std::uniform_int_distribution<int> pixel(0, w - 1);
    std::uniform_real_distribution<double> depth(-1, 0.99);
    int side = 0, caps = 0, exits = 0, misses = 0, disagree = 0;
    for (int round = 0; round < 300; ++round) {
      const int count = 1 + round % 64;  // a ray window's 16, or a cell's 64
      const double zlo = round % 2 == 0 ? -1 : depth(rng);
      double x[64], y[64], zhi[64], z[64];
      for (int i = 0; i < count; ++i) {
        x[i] = 2.0 * (pixel(rng) + 0.5) / w - 1;
        y[i] = 1 - 2.0 * (pixel(rng) + 0.5) / h;
        zhi[i] = i % 7 == 6 ? zlo : 1;  // some spans are empty
      }
      g->quadricCrossings(x, y, zlo, zhi, count, z);
      for (int i = 0; i < count; ++i) {
        results.push_back(z[i]);
        const double want =
            zhi[i] > zlo ? firstSignChange(*g, x[i], y[i], zhi[i], zlo) : double(NAN);
        if (std::isnan(want) != std::isnan(z[i])) {
          ++disagree;  // only a ray grazing the surface within the truth's step may
          continue;
        }
        if (std::isnan(want)) {
          ++misses;
          continue;
        }
        EXPECT_NEAR(z[i], want, 1e-9)
            << hwy::TargetName(target) << " round " << round << " ray " << i;
        const Vec3d p = g->toObject({x[i], y[i], z[i]});
        if (f.base.evaluate(p) < 0 || g->evaluate({x[i], y[i], zlo}) >= 0)
          ++exits;  // leaves the cylinder here, or started inside it
        else if (std::fabs(f.base.evaluate(p)) < 1e-6)
          ++side;
        else
          ++caps;
      }
    }
    EXPECT_LE(disagree, 2);
    EXPECT_GT(side, 150);
    EXPECT_GT(caps, 200);
    EXPECT_GT(exits, 30);
    EXPECT_GT(misses, 500);
  });
}

// ProjectedFreeForm::quadricHits: an 8×8 block of rays takes exactly the crossings
// quadricCrossings finds for it, where nearer than its pixels' depths (the window depth rounded
// to float, as the caster's takeHit) — depth and masking node, object, cube depth and active bits
// written there and nowhere else, with or without the optional buffers, at any row strides; the
// last hit taken in raster order reported. The same bits on every compiled target.
TEST(RayCast, QuadricHitsTakeTheNearerCrossingsOnEveryTarget) {
  const int w = 64, h = 64;
  const auto g = ProjectedFreeForm::make(cappedCylinder(), cameraToCube(w, h));
  ASSERT_TRUE(g);
  onEveryTarget([&](int64_t target, std::vector<double>& results) {
    std::mt19937 rng(16);
    std::uniform_int_distribution<int> origin(0, w - 8);
    std::uniform_real_distribution<double> unit(0, 1);
    int taken = 0, behind = 0;
    for (int round = 0; round < 200; ++round) {
      const int x0 = origin(rng), y0 = origin(rng);
      const double zlo = round % 3 == 0 ? -1 : -1 + unit(rng), zhi = round % 5 == 0 ? 0.95 : 1;
      double columns[8], rows[8];
      for (int i = 0; i < 8; ++i) {
        columns[i] = 2.0 * (x0 + i + 0.5) / w - 1;
        rows[i] = 1 - 2.0 * (y0 + i + 0.5) / h;
      }
      // Buffers wider than the block (strides 11 and 13), pixels holding depths near and far.
      const size_t stride = 11, nodeStride = 13;
      std::vector<float> depth(8 * stride), node(8 * nodeStride, -1.0f);
      for (float& v : depth) v = unit(rng) < 0.3 ? 1.0f : float(0.5 + 0.5 * unit(rng));
      std::vector<uint32_t> object(8 * stride, kNoHit);
      std::vector<double> cubeZ(8 * stride, -7);
      std::vector<uint64_t> active(8 * stride, 5);
      const bool optional = round % 4 != 1;
      HitRows to;
      to.depth = depth.data();
      to.object = optional ? object.data() : nullptr;
      to.cubeZ = optional ? cubeZ.data() : nullptr;
      to.active = optional ? active.data() : nullptr;
      to.stride = stride;
      to.node = node.data();
      to.nodeStride = nodeStride;
      to.id = 9;
      to.activeBits = 0x30;
      const std::vector<float> before = depth;
      double last = -5, lastWanted = -5;
      const int hits = g->quadricHits(columns, rows, zlo, zhi, to, last);
      int wanted = 0;
      for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i) {
          const size_t at = size_t(j) * stride + size_t(i);
          const double end = std::min(zhi, 2.0 * double(before[at]) - 1);
          double z;
          g->quadricCrossings(&columns[i], &rows[j], zlo, &end, 1, &z);
          const float d = float(0.5 * (z + 1));
          const std::string where = std::string(hwy::TargetName(target)) + " round " +
                                    std::to_string(round) + " pixel " + std::to_string(i) + "," +
                                    std::to_string(j);
          if (d < before[at]) {
            ++wanted;
            lastWanted = z;
            EXPECT_EQ(depth[at], d) << where;
            EXPECT_EQ(node[size_t(j) * nodeStride + size_t(i)], d) << where;
            if (optional) {
              EXPECT_EQ(object[at], 9u) << where;
              EXPECT_EQ(cubeZ[at], z) << where;
              EXPECT_EQ(active[at], 0x30u) << where;
            }
          } else {
            double open;  // the crossing with the pixel's depth left out
            g->quadricCrossings(&columns[i], &rows[j], zlo, &zhi, 1, &open);
            behind += std::isnan(open) ? 0 : 1;
            EXPECT_EQ(depth[at], before[at]) << where;
            EXPECT_EQ(node[size_t(j) * nodeStride + size_t(i)], -1.0f) << where;
            EXPECT_EQ(object[at], kNoHit) << where;
            EXPECT_EQ(cubeZ[at], -7) << where;
            EXPECT_EQ(active[at], 5u) << where;
          }
        }
      EXPECT_EQ(hits, wanted) << "round " << round;
      EXPECT_EQ(last, lastWanted) << "round " << round;
      taken += hits;
      results.insert(results.end(), cubeZ.begin(), cubeZ.end());
      for (float v : depth) results.push_back(v);
    }
    EXPECT_GT(taken, 1000);
    EXPECT_GT(behind, 100);  // surfaces behind what the pixels hold, left there
  });
}

// quadricsAlone: H is its quadrics alone only where no root perturbation is active — and never
// with more root perturbations than `active` has bits for, nor with more clips than the closed
// form holds.
TEST(RayCast, QuadricsAloneOnlyWhereNoPerturbationIsActive) {
  const auto g = ProjectedFreeForm::make(bumpedSphere(), cameraToCube(64, 64));
  ASSERT_TRUE(g);
  EXPECT_TRUE(g->quadricsAlone(0));
  EXPECT_FALSE(g->quadricsAlone(1));
  EXPECT_FALSE(g->quadricsAlone(kAllActive));
  EXPECT_TRUE(g->quadricsAlone(~uint64_t(1)));  // bits of perturbations the form lacks
  FreeForm many;
  many.base = Quadric::sphere({0, 0, 0}, 1);
  for (int i = 0; i < 65; ++i) many.perturbations.push_back(bumpedSphere().perturbations[0]);
  const auto m = ProjectedFreeForm::make(many, cameraToCube(64, 64));
  ASSERT_TRUE(m);
  EXPECT_FALSE(m->quadricsAlone(0));  // the 65th is always taken
  FreeForm clipped = cappedCylinder();
  while (clipped.clips.size() <= ProjectedFreeForm::kMaxClipsSolved)
    clipped.clips.push_back(Quadric::halfSpace({0, 0, 1}, 2.0 + double(clipped.clips.size())));
  const auto c = ProjectedFreeForm::make(clipped, cameraToCube(64, 64));
  ASSERT_TRUE(c);
  EXPECT_FALSE(c->quadricsAlone(0));  // more clips than the closed form holds
}

// CastWindow::active: every hit keeps the perturbations that may be positive in its ray window;
// each one left out is ≤ 0 at the hit (so it adds nothing there, nor to the gradient), and on a
// sphere with six bumps most hits leave most out.
TEST(RayCast, HitsKeepThePerturbationsThatMayBePositiveThere) {
  const int w = 128, h = 128;
  const FreeForm f = sculpture();
  const Mat4d toCube = cameraToCube(w, h);
  const auto g = ProjectedFreeForm::make(f, toCube);
  ASSERT_TRUE(g);
  Buffers b(w, h);
  std::vector<uint64_t> active(size_t(w) * h, 0);
  CastStats stats;
  for (int y0 = 0; y0 < h; y0 += 64)
    for (int x0 = 0; x0 < w; x0 += 64) {
      CastWindow window = windowOf(b, x0, y0);
      window.active = active.data() + size_t(y0) * w + size_t(x0);
      castWindow(*g, 1, window, CastSettings{}, stats);
    }
  int hits = 0, leftOut = 0;
  for (int py = 0; py < h; ++py)
    for (int px = 0; px < w; ++px) {
      const size_t at = size_t(py) * w + size_t(px);
      if (b.object[at] != 1) continue;
      ++hits;
      const Vec3d p =
          g->toObject({2.0 * (px + 0.5) / w - 1, 1 - 2.0 * (py + 0.5) / h, b.cubeZ[at]});
      for (int k = 0; k < 6; ++k) {
        if (active[at] >> k & 1) continue;
        ++leftOut;
        EXPECT_LE(f.perturbations[size_t(k)].base.evaluate(p), 1e-9)
            << "pixel " << px << "," << py << " perturbation " << k;
      }
    }
  EXPECT_GT(hits, 2000);
  EXPECT_GT(leftOut, 4 * hits);
}

// A sculpture: masking skips hidden cells but never changes a pixel, with a masking pyramid per
// form or one shared by the forms of a window; the fixed-step marcher finds the same surface
// where its steps do not skip it.
TEST(RayCast, MaskingChangesNothingAndTheMarcherAgrees) {
  const int w = 96, h = 64;
  const FreeForm f = sculpture();
  FreeForm ground;
  ground.base = Quadric::halfSpace({0, 1, 0}, -0.7);
  const Mat4d toCube = cameraToCube(w, h);
  const auto g = ProjectedFreeForm::make(f, toCube),
             floor = ProjectedFreeForm::make(ground, toCube);
  ASSERT_TRUE(g && floor);
  Buffers masked(w, h), plain(w, h), marched(w, h);
  CastStats ms = cast(*g, 1, masked), ps = cast(*g, 1, plain, false);
  ms.add(cast(*floor, 2, masked));
  ps.add(cast(*floor, 2, plain, false));
  EXPECT_EQ(masked.depth, plain.depth);
  EXPECT_EQ(masked.object, plain.object);
  // Both forms cast window by window into one masking pyramid per window (as the tile pass
  // does): the same buffers.
  Buffers shared(w, h);
  for (int y0 = 0; y0 < h; y0 += 64)
    for (int x0 = 0; x0 < w; x0 += 64) {
      const CastWindow window = windowOf(shared, x0, y0);
      MaskingPyramid pyramid(window);
      CastStats stats;
      castWindow(*g, 1, window, CastSettings{}, stats, &pyramid);
      castWindow(*floor, 2, window, CastSettings{}, stats, &pyramid);
    }
  EXPECT_EQ(shared.depth, masked.depth);
  EXPECT_EQ(shared.object, masked.object);
  EXPECT_GT(ms.maskedCells, 0u);
  EXPECT_LT(ms.depthTests, ps.depthTests);
  cast(*g, 1, marched, true, 2048);
  cast(*floor, 2, marched, true, 2048);
  int differ = 0;
  for (size_t i = 0; i < marched.object.size(); ++i) {
    if (marched.object[i] != masked.object[i]) {
      ++differ;
      continue;
    }
    if (masked.object[i] != kNoHit) {
      EXPECT_NEAR(marched.cubeZ[i], masked.cubeZ[i], 1e-9) << i;
    }
  }
  EXPECT_LE(differ, 4);
}

// The polygon baseline: marching tetrahedra on octree leaves puts every vertex on the surface,
// faces outward, and closes a sphere with chords no farther from it than the cell allows.
TEST(Tessellate, SphereVerticesLieOnTheSurfaceWithOutwardFaces) {
  FreeForm f;
  f.base = Quadric::sphere({0.3, -0.2, 0.1}, 1.5);
  bool unbounded = true;
  const std::optional<Box> box = surfaceBounds(f, 100, 12, unbounded);
  ASSERT_TRUE(box);
  EXPECT_FALSE(unbounded);
  FreeForm plane;
  plane.base = Quadric::halfSpace({0, 1, 0}, 0);
  EXPECT_FALSE(surfaceBounds(plane, 100, 12, unbounded));
  EXPECT_TRUE(unbounded);
  EXPECT_NEAR((*box)[0].x, 0.3 - 1.5, 0.06);
  EXPECT_NEAR((*box)[1].y, -0.2 + 1.5, 0.06);
  TriangleSoup soup;
  ASSERT_TRUE(tessellate(f, *box, 0.1, 1000000, soup));
  EXPECT_GT(soup.triangles(), 1000u);
  double area = 0;
  for (size_t t = 0; t < soup.triangles(); ++t) {
    const Vec3d a = soup.positions[3 * t], b = soup.positions[3 * t + 1],
                c = soup.positions[3 * t + 2];
    for (const Vec3d& p : {a, b, c}) {
      const Vec3d d = p - Vec3d{0.3, -0.2, 0.1};
      EXPECT_NEAR(std::sqrt(dot(d, d)), 1.5, 1e-5);
    }
    const Vec3d u = b - a, v = c - a;
    const Vec3d n{u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x};
    const Vec3d out = (a + b + c) * (1.0 / 3) - Vec3d{0.3, -0.2, 0.1};
    EXPECT_GE(dot(n, out), 0) << "triangle " << t << " faces inward";
    area += 0.5 * std::sqrt(dot(n, n));
  }
  // Chords cut inside the sphere: a little less than 4πr², by under 1 % at this cell size.
  EXPECT_LT(area, 4 * M_PI * 1.5 * 1.5);
  EXPECT_GT(area, 0.99 * 4 * M_PI * 1.5 * 1.5);
}

}  // namespace
}  // namespace sv::freeform
