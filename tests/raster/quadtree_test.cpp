// The quadtree rasterizer against the rules of RASTER-NOTES.md: fill rule, watertightness, the
// near plane, bad vertices, and pixel-for-pixel equality with a brute-force reference.
#include <gtest/gtest.h>

#include <cstdlib>

#include <cmath>
#include <numbers>
#include <random>

#include "hwy/targets.h"
#include "support/raster_harness.h"
#include "synthvis/math.h"

namespace sv {
namespace {

using test::randomScene;

using geometry::ClipVertex;
using render::DrawPackets;
using render::FrameSettings;
using test::addTriangle;
using test::pixelVertex;

FrameSettings countSettings(int w, int h) {
  FrameSettings s;
  s.width = w;
  s.height = h;
  s.shade = raster::ShadeMode::overdraw;
  return s;
}

FrameSettings gouraudSettings(int w, int h) {
  FrameSettings s;
  s.width = w;
  s.height = h;
  s.clearColor[0] = 0.1f;
  s.clearColor[1] = 0.2f;
  s.clearColor[2] = 0.3f;
  return s;
}

int countPixels(const test::Frame& f, int value) {
  int n = 0;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) n += f.channel(x, y, 0) == value;
  return n;
}

TEST(FillRule, SquareSplitOnItsDiagonalGivesFifteenAndTenPixels) {
  const int w = 16, h = 16;
  auto v = [&](double x, double y) { return pixelVertex(x, y, w, h); };
  DrawPackets a, b;
  addTriangle(a, v(0, 0), v(5, 0), v(5, 5));  // upper right half, diagonal included or not
  addTriangle(b, v(0, 0), v(5, 5), v(0, 5));
  const int na = countPixels(test::renderQuadtree(a, countSettings(w, h)), 1);
  const int nb = countPixels(test::renderQuadtree(b, countSettings(w, h)), 1);
  EXPECT_EQ(na + nb, 25);
  EXPECT_EQ(std::max(na, nb), 15);
  EXPECT_EQ(std::min(na, nb), 10);
  // Together: every pixel of the square exactly once.
  DrawPackets both = a;
  addTriangle(both, v(0, 0), v(5, 5), v(0, 5));
  const test::Frame f = test::renderQuadtree(both, countSettings(w, h));
  EXPECT_EQ(countPixels(f, 1), 25);
  EXPECT_EQ(countPixels(f, 2), 0);
}

TEST(FillRule, ReversedWindingDrawsTheSamePixels) {
  const int w = 16, h = 16;
  auto v = [&](double x, double y) { return pixelVertex(x, y, w, h); };
  DrawPackets a, b;
  addTriangle(a, v(0.5, 0.5), v(9.5, 2.5), v(3.5, 8.5));
  addTriangle(b, v(0.5, 0.5), v(3.5, 8.5), v(9.5, 2.5));
  EXPECT_EQ(test::renderQuadtree(a, countSettings(w, h)),
            test::renderQuadtree(b, countSettings(w, h)));
}

// A jittered N×N grid of quads (two triangles each), jitter ≤ 0.2 cell so nothing folds, boundary
// vertices fixed, then rotated and offset: every pixel centre inside the outline is counted once.
void expectWatertightGrid(int width, int height, int cells, double angle, double offX, double offY,
                          unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  const double size = 0.8 * std::min(width, height), cell = size / cells;
  const double cx = width / 2.0 + offX, cy = height / 2.0 + offY;
  const double ca = std::cos(angle), sa = std::sin(angle);
  std::vector<std::array<double, 2>> pts((cells + 1) * (cells + 1));
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i) {
      double u = i * cell - size / 2, v = j * cell - size / 2;
      if (i > 0 && i < cells && j > 0 && j < cells) {
        u += jitter(rng) * cell;
        v += jitter(rng) * cell;
      }
      pts[j * (cells + 1) + i] = {cx + ca * u - sa * v, cy + sa * u + ca * v};
    }
  DrawPackets p;
  for (auto& q : pts) p.vertices.push_back(pixelVertex(q[0], q[1], width, height));
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      const uint32_t a = j * (cells + 1) + i, b = a + 1, c = a + cells + 1, d = c + 1;
      // Alternate the diagonal so both orientations of shared edges occur.
      if ((i + j) & 1)
        p.indices.insert(p.indices.end(), {a, b, d, a, d, c});
      else
        p.indices.insert(p.indices.end(), {a, b, c, b, d, c});
    }
  p.calls.push_back({0, uint32_t(p.indices.size() / 3), geometry::CullMode::none});
  ASSERT_GE(p.indices.size() / 3, size_t(2 * cells * cells));

  const test::Frame f = test::renderQuadtree(p, countSettings(width, height), 2);
  // Expected: inside the rotated square outline. Vertices snap to 1/256 px, which moves the outline
  // by up to 1/256 px, so centres that close to it may go either way; every other pixel — all the
  // interior, where the shared edges are — must be counted exactly once.
  int wrong = 0, inside = 0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
      const double u = ca * dx + sa * dy, v = -sa * dx + ca * dy;
      const double margin = size / 2 - std::max(std::fabs(u), std::fabs(v));
      if (std::fabs(margin) < 1.0 / 256) continue;
      const int expected = margin > 0 ? 1 : 0;
      inside += expected;
      if (f.channel(x, y, 0) != expected) {
        ++wrong;
        ADD_FAILURE() << "pixel " << x << "," << y << " count " << f.channel(x, y, 0) << " margin "
                      << margin;
      }
    }
  EXPECT_GT(inside, 0);
  EXPECT_EQ(wrong, 0) << "grid " << cells << " at " << width << "x" << height << " angle " << angle;
}

TEST(Watertight, JitteredGridOfTinyTrianglesCoversEveryPixelExactlyOnce) {
  // 230×230 cells = 105 800 triangles of ≈ 0.4–5 px² at these resolutions.
  expectWatertightGrid(300, 300, 230, 0.3, 0.123, 0.377, 1);
  expectWatertightGrid(517, 333, 230, 1.1, -0.31, 0.07, 2);
  expectWatertightGrid(1024, 768, 230, 2.0, 0.5, 0.25, 3);
}

TEST(Watertight, CoarseAndDenseGridsAtManyOffsets) {
  for (int i = 0; i < 6; ++i) {
    expectWatertightGrid(200, 150, 10 + 15 * i, 0.17 * i + 0.05, 0.093 * i, -0.071 * i, 10 + i);
  }
}

// A tessellated sphere around the camera: with both faces drawn every pixel is covered exactly
// once — edges of triangles behind the eye and crossing the eye plane included.
TEST(NearPlane, CameraInsideClosedSphereHitsEveryPixelOnce) {
  const int w = 160, h = 120;
  const int stacks = 24, slices = 48;
  const Mat4 proj = Mat4::perspective(1.2f, float(w) / h, 0.1f, 100.0f);
  const Mat4 view = Mat4::lookAt({0.1f, 0.05f, -0.02f}, {1, 0.3f, 0.2f}, {0, 1, 0});
  const Mat4 vp = proj * view;
  DrawPackets p;
  for (int i = 0; i <= stacks; ++i)
    for (int j = 0; j <= slices; ++j) {
      const float th = std::numbers::pi_v<float> * i / stacks,
                  ph = 2 * std::numbers::pi_v<float> * j / slices;
      const Vec4 c = vp * Vec4{2 * std::sin(th) * std::cos(ph), 2 * std::cos(th),
                               2 * std::sin(th) * std::sin(ph), 1};
      p.vertices.push_back({c.x, c.y, c.z, c.w, 1, 1, 1, 1});
    }
  for (int i = 0; i < stacks; ++i)
    for (int j = 0; j < slices; ++j) {
      const uint32_t a = i * (slices + 1) + j, b = a + 1, c = a + slices + 1, d = c + 1;
      if (i > 0) p.indices.insert(p.indices.end(), {a, c, b});
      if (i < stacks - 1) p.indices.insert(p.indices.end(), {b, c, d});
    }
  p.calls.push_back({0, uint32_t(p.indices.size() / 3), geometry::CullMode::none});
  const test::Frame f = test::renderQuadtree(p, countSettings(w, h));
  EXPECT_EQ(countPixels(f, 1), w * h);
}

TEST(Quadtree, EqualsBruteForcePixelForPixelOnRandomScenes) {
  for (unsigned seed = 1; seed <= 4; ++seed) {
    const int w = 97 + 61 * seed, h = 71 + 37 * seed;  // not multiples of tiles or blocks
    const DrawPackets p = randomScene(w, h, 120, seed, false);
    const test::Frame quad = test::renderQuadtree(p, gouraudSettings(w, h));
    const test::Frame ref = test::renderReference(p, gouraudSettings(w, h));
    EXPECT_TRUE(quad == ref) << "seed " << seed;
  }
}

TEST(Quadtree, EqualsBruteForceWithTrianglesBehindAndAcrossTheEye) {
  for (unsigned seed = 11; seed <= 14; ++seed) {
    const int w = 130, h = 90;
    const DrawPackets p = randomScene(w, h, 150, seed, true);
    EXPECT_TRUE(test::renderQuadtree(p, gouraudSettings(w, h)) ==
                test::renderReference(p, gouraudSettings(w, h)))
        << "seed " << seed;
    EXPECT_TRUE(test::renderQuadtree(p, countSettings(w, h)) ==
                test::renderReference(p, countSettings(w, h)))
        << "seed " << seed;
  }
}

TEST(Quadtree, EveryLegLengthFromOneTo4096PixelsEqualsBruteForce) {
  const int w = 300, h = 200;
  for (int leg = 1; leg <= 4096; leg *= 2) {
    DrawPackets p;
    std::mt19937 rng(leg);
    std::uniform_real_distribution<double> u(0, 1);
    for (int i = 0; i < 20; ++i) {
      const double x = u(rng) * w, y = u(rng) * h, a = u(rng) * 6.28;
      addTriangle(
          p, pixelVertex(x, y, w, h, 0.3f),
          pixelVertex(x + leg * std::cos(a), y + leg * std::sin(a), w, h, 0.6f),
          pixelVertex(x + leg * std::cos(a + 1.3), y + leg * std::sin(a + 1.3), w, h, 0.9f));
    }
    EXPECT_TRUE(test::renderQuadtree(p, countSettings(w, h)) ==
                test::renderReference(p, countSettings(w, h)))
        << "leg " << leg;
  }
}

// Triangles at the edge of the int32 budget (geometry/setup.h: extent up to kSmallExtent = 96 px,
// evaluated anywhere in the tiles their box meets), at every offset to the tile grid, with and
// without anti-aliasing: the int32 stepping equals the brute-force reference.
TEST(Quadtree, SmallTrianglesAtTheInt32BudgetEqualBruteForce) {
  const int w = 320, h = 256;
  DrawPackets p;
  const double e = geometry::kSmallExtent - 0.01;
  for (int off = 0; off < 64; off += 9) {
    const double x = 40 + off, y = 30 + off * 0.7;
    addTriangle(p, pixelVertex(x, y, w, h, 0.2f), pixelVertex(x + e, y + 0.3, w, h, 0.5f),
                pixelVertex(x + 0.2, y + e, w, h, 0.8f));
    addTriangle(p, pixelVertex(x + e, y + e, w, h, 0.3f), pixelVertex(x, y + e * 0.5, w, h, 0.4f),
                pixelVertex(x + e * 0.5, y + 0.1, w, h, 0.6f));  // a sliver across the box
  }
  EXPECT_TRUE(test::renderQuadtree(p, countSettings(w, h)) ==
              test::renderReference(p, countSettings(w, h)));
  FrameSettings aa = gouraudSettings(w, h);
  aa.samples = 16;
  EXPECT_TRUE(test::renderQuadtree(p, aa) == test::renderReference(p, aa));
}

TEST(BadVertices, NonFiniteAndHugeCoordinatesAreDroppedOrDrawnDeterministically) {
  const int w = 64, h = 64;
  const float inf = std::numeric_limits<float>::infinity(), nan = std::nanf("");
  DrawPackets p;
  const ClipVertex good = pixelVertex(10, 10, w, h), good2 = pixelVertex(50, 12, w, h);
  const ClipVertex bad[] = {
      {nan, 0, 0, 1, 1, 1, 1, 1},       {0, inf, 0, 1, 1, 1, 1, 1},
      {0, 0, -inf, 1, 1, 1, 1, 1},      {0, 0, 0, nan, 1, 1, 1, 1},
      {1e30f, 1e30f, 0, 1, 1, 1, 1, 1}, {-1e30f, 3e29f, 0, 1e-30f, 1, 1, 1, 1},
      {0, 0, 0, 0, 1, 1, 1, 1},         {0.5f, 0.5f, 0, -1e-30f, 1, 1, 1, 1}};
  for (const ClipVertex& b : bad) addTriangle(p, good, good2, b);
  // Degenerate: all three on a line, and all three equal.
  addTriangle(p, good, good2, pixelVertex(90, 14, w, h));
  addTriangle(p, good, good, good);
  FrameStats stats;
  const test::Frame f = test::renderQuadtree(p, countSettings(w, h), 2, &stats);
  EXPECT_EQ(stats.culledInvalid, 4u);
  EXPECT_GE(stats.culledDegenerate + stats.culledOutside, 2u);
  EXPECT_TRUE(f == test::renderReference(p, countSettings(w, h)));
}

TEST(BadVertices, HugeTriangleOfTenMillionPixelsCoversTheScreenOnce) {
  const int w = 200, h = 100;
  DrawPackets p;
  addTriangle(p, pixelVertex(-3000, -3000, w, h), pixelVertex(6000, -3000, w, h),
              pixelVertex(-3000, 4000, w, h));
  const test::Frame f = test::renderQuadtree(p, countSettings(w, h));
  EXPECT_EQ(countPixels(f, 1), w * h);
}

TEST(BadVertices, SliversOneTwoHundredFiftySixthOfAPixelThickMatchTheReference) {
  const int w = 1024, h = 64;
  DrawPackets p;
  for (int i = 0; i < 16; ++i) {
    const double y = 3.3 + i * 3.7;
    addTriangle(p, pixelVertex(-500, y, w, h), pixelVertex(1500, y + 0.5, w, h),
                pixelVertex(-500, y + 1.0 / 256, w, h));
  }
  EXPECT_TRUE(test::renderQuadtree(p, countSettings(w, h)) ==
              test::renderReference(p, countSettings(w, h)));
}

TEST(Determinism, OneTwoAndEightThreadsGiveIdenticalFrames) {
  const int w = 333, h = 250;
  const DrawPackets p = randomScene(w, h, 3000, 99, true);
  const test::Frame one = test::renderQuadtree(p, gouraudSettings(w, h), 1);
  EXPECT_TRUE(one == test::renderQuadtree(p, gouraudSettings(w, h), 2));
  EXPECT_TRUE(one == test::renderQuadtree(p, gouraudSettings(w, h), 8));
}

// Frames of several batches keep a whole-frame buffer between batches; frames of one draw each
// tile in a per-thread buffer. Both give the same frame, and the reference's.
TEST(Determinism, ManyBatchesGiveTheOneBatchFrame) {
  const int w = 333, h = 250;
  const DrawPackets p = randomScene(w, h, 3000, 7, true);
  const test::Frame one = test::renderQuadtree(p, gouraudSettings(w, h), 2);
  for (uint32_t batch : {1u, 97u, 1000u}) {
    FrameSettings s = gouraudSettings(w, h);
    s.batchTriangles = batch;
    EXPECT_TRUE(one == test::renderQuadtree(p, s, 2)) << "batches of " << batch;
  }
  EXPECT_TRUE(one == test::renderReference(p, gouraudSettings(w, h)));
}

// scripts/test runs the kernels' tests a second time with SV_TEST_SIMD_TARGET=scalar
// (support/test_main.cpp): then the scalar fallback is the only target the kernels dispatch to.
TEST(Determinism, TheScalarPathIsTheOnlyTargetWhenAsked) {
  const char* target = std::getenv("SV_TEST_SIMD_TARGET");
  if (!target || !*target) GTEST_SKIP() << "SV_TEST_SIMD_TARGET is not set";
  EXPECT_EQ(hwy::SupportedTargets(), int64_t(HWY_BASELINE_SCALAR))
      << hwy::TargetName(hwy::SupportedTargets());
  EXPECT_EQ(hwy::SupportedAndGeneratedTargets(), std::vector<int64_t>{HWY_BASELINE_SCALAR});
}

TEST(Determinism, EverySimdTargetGivesTheScalarTargetsFrame) {
  const int w = 200, h = 150;
  const DrawPackets p = randomScene(w, h, 400, 5, true);
  const test::Frame ref = test::renderReference(p, gouraudSettings(w, h));
  int tested = 0;
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    EXPECT_TRUE(test::renderQuadtree(p, gouraudSettings(w, h), 2) == ref)
        << "target " << hwy::TargetName(target);
    ++tested;
  }
  hwy::SetSupportedTargetsForTest(0);
  EXPECT_GE(tested, 1);
}

}  // namespace
}  // namespace sv
