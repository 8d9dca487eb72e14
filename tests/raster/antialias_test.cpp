// Anti-aliased rasterization (SPEC §3.2 aperture, §5 masks): the kernel's per-sample frame equals a
// brute-force reference built on EdgeMaskTable::mask, on every SIMD target, for any thread count
// and batching; a tessellated quad shows no cracks against the single quad.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>

#include "hwy/targets.h"
#include "support/raster_harness.h"

namespace sv {
namespace {

using geometry::ClipVertex;
using render::DrawPackets;
using render::FrameSettings;
using test::addTriangle;
using test::pixelVertex;
using test::randomScene;

constexpr int kAaCounts[] = {4, 8, 16, 64};  // kSampleCounts but 1

FrameSettings aaSettings(int w, int h, int samples) {
  FrameSettings s;
  s.width = w;
  s.height = h;
  s.samples = samples;
  s.clearColor[0] = 0.1f;
  s.clearColor[1] = 0.2f;
  s.clearColor[2] = 0.3f;
  return s;
}

// The first differing sample, for a readable failure.
std::string firstDifference(const test::Frame& a, const test::Frame& b) {
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x)
      for (int s = 0; s < a.samples; ++s) {
        const size_t i = (size_t(y) * a.width + x) * a.samples + s;
        if (a.depth[i] != b.depth[i] || a.channel(x, y, 0, s) != b.channel(x, y, 0, s) ||
            a.channel(x, y, 1, s) != b.channel(x, y, 1, s) ||
            a.channel(x, y, 2, s) != b.channel(x, y, 2, s))
          return "pixel " + std::to_string(x) + "," + std::to_string(y) + " sample " +
                 std::to_string(s) + ": depth " + std::to_string(a.depth[i]) + " vs " +
                 std::to_string(b.depth[i]) + ", red " + std::to_string(a.channel(x, y, 0, s)) +
                 " vs " + std::to_string(b.channel(x, y, 0, s));
      }
  return "equal";
}

TEST(AntiAlias, EqualsBruteForceSampleForSampleOnRandomScenes) {
  for (int n : kAaCounts)
    for (unsigned seed = 1; seed <= 3; ++seed) {
      const int w = 97 + 61 * int(seed), h = 71 + 37 * int(seed);
      const DrawPackets p = randomScene(w, h, 100, seed, false);
      const test::Frame quad = test::renderQuadtree(p, aaSettings(w, h, n));
      const test::Frame ref = test::renderReference(p, aaSettings(w, h, n));
      EXPECT_TRUE(quad == ref) << n << " samples, seed " << seed << ": "
                               << firstDifference(quad, ref);
    }
}

TEST(AntiAlias, EqualsBruteForceWithTrianglesBehindAndAcrossTheEye) {
  for (int n : {4, 64})
    for (unsigned seed = 11; seed <= 13; ++seed) {
      const int w = 130, h = 90;
      const DrawPackets p = randomScene(w, h, 150, seed, true);
      const test::Frame quad = test::renderQuadtree(p, aaSettings(w, h, n));
      const test::Frame ref = test::renderReference(p, aaSettings(w, h, n));
      EXPECT_TRUE(quad == ref) << n << " samples, seed " << seed << ": "
                               << firstDifference(quad, ref);
    }
}

TEST(AntiAlias, EverySimdTargetThreadCountAndBatchingGivesTheSameFrame) {
  const int w = 200, h = 150;
  const DrawPackets p = randomScene(w, h, 600, 5, true);
  const test::Frame ref = test::renderReference(p, aaSettings(w, h, 16));
  int tested = 0;
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    const test::Frame f = test::renderQuadtree(p, aaSettings(w, h, 16), 2);
    EXPECT_TRUE(f == ref) << "target " << hwy::TargetName(target) << ": "
                          << firstDifference(f, ref);
    ++tested;
  }
  hwy::SetSupportedTargetsForTest(0);
  EXPECT_GE(tested, 1);
  EXPECT_TRUE(test::renderQuadtree(p, aaSettings(w, h, 16), 1) == ref);
  EXPECT_TRUE(test::renderQuadtree(p, aaSettings(w, h, 16), 8) == ref);
  FrameSettings batched = aaSettings(w, h, 16);
  batched.batchTriangles = 97;  // the whole-frame sample buffer between batches
  EXPECT_TRUE(test::renderQuadtree(p, batched, 2) == ref);
}

// A square tessellated into a jittered grid of small triangles, white on black, against the same
// square as two triangles: shared edges' masks are exact complements, so the grid shows no crack
// and no seam along its edges — those pixels equal the single quad's (the outline is the same
// straight lines, and collinear edges read the same masks). Axis-aligned and rotated by 30°
// (interior only, since there the snapped outline vertices are not exactly collinear).
// Near a vertex the table's masks are not exact: a sample within EdgeMaskTable::kMaxError of two of
// the edges meeting there is decided for each edge from its own table cell, and may end in no
// triangle or in two (docs/quality.md). Pixels within half a pixel of a grid vertex may so differ
// by at most two samples.
void expectSeamless(int samples, double angle, unsigned seed) {
  const int w = 96, h = 96, cells = 24;
  const double size = 80, cell = size / cells, cx = 48, cy = 48;
  const double ca = std::cos(angle), sa = std::sin(angle);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  auto place = [&](double u, double v) {
    return pixelVertex(cx + ca * u - sa * v, cy + sa * u + ca * v, w, h, 0.5f, 1, 1, 1, 1);
  };
  DrawPackets grid, quad;
  std::vector<std::array<double, 2>> corners;  // grid vertices, in pixels
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i) {
      double u = i * cell - size / 2, v = j * cell - size / 2;
      if (i > 0 && i < cells && j > 0 && j < cells) {
        u += jitter(rng) * cell;
        v += jitter(rng) * cell;
      }
      grid.vertices.push_back(place(u, v));
      corners.push_back({cx + ca * u - sa * v, cy + sa * u + ca * v});
    }
  auto nearVertex = [&](int x, int y) {
    for (const auto& c : corners)
      if (c[0] > x - 0.5 && c[0] < x + 1.5 && c[1] > y - 0.5 && c[1] < y + 1.5) return true;
    return false;
  };
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      const uint32_t a = uint32_t(j * (cells + 1) + i), b = a + 1, c = a + cells + 1, d = c + 1;
      if ((i + j) & 1)
        grid.indices.insert(grid.indices.end(), {a, b, d, a, d, c});
      else
        grid.indices.insert(grid.indices.end(), {a, b, c, b, d, c});
    }
  grid.calls.push_back({0, uint32_t(grid.indices.size() / 3), geometry::CullMode::none});
  const ClipVertex q[4] = {place(-size / 2, -size / 2), place(size / 2, -size / 2),
                           place(-size / 2, size / 2), place(size / 2, size / 2)};
  addTriangle(quad, q[0], q[1], q[2]);
  addTriangle(quad, q[1], q[3], q[2]);
  FrameSettings s = aaSettings(w, h, samples);
  s.clearColor[0] = s.clearColor[1] = s.clearColor[2] = 0;
  const test::Frame g = test::renderQuadtree(grid, s, 2), one = test::renderQuadtree(quad, s, 2);
  int partial = 0, wrong = 0, vertexPixels = 0, vertexDiffering = 0;
  const int sampleStep = 65535 / samples + 1;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
      const double margin =
          size / 2 - std::max(std::fabs(ca * dx + sa * dy), std::fabs(-sa * dx + ca * dy));
      const bool interior = margin > 1.5;
      const uint16_t expected = one.resolved(x, y, 0);
      partial += expected > 0 && expected < 65535;
      if (interior && expected != 65535) ++wrong;  // the reference itself has no hole
      if (!interior && angle != 0) continue;
      const int diff = std::abs(int(g.resolved(x, y, 0)) - int(expected));
      if (nearVertex(x, y)) {
        ++vertexPixels;
        vertexDiffering += diff != 0;
        if (diff > 2 * sampleStep && ++wrong < 5)
          ADD_FAILURE() << samples << " samples, angle " << angle << ": pixel " << x << "," << y
                        << " by a vertex: grid " << g.resolved(x, y, 0) << " quad " << expected;
      } else if (diff != 0) {
        if (++wrong < 5)
          ADD_FAILURE() << samples << " samples, angle " << angle << ": pixel " << x << "," << y
                        << " grid " << g.resolved(x, y, 0) << " quad " << expected;
      }
    }
  EXPECT_EQ(wrong, 0);
  EXPECT_GT(vertexPixels, 100);
  EXPECT_LT(vertexDiffering * 10, vertexPixels) << "most vertex pixels are exact too";
  if (angle != 0) {
    EXPECT_GT(partial, 0) << "the rotated outline has partly covered pixels";
  }
}

TEST(AntiAlias, TessellatedQuadHasNoCracksAgainstTheSingleQuad) {
  for (int n : kAaCounts) {
    expectSeamless(n, 0.0, 1);
    expectSeamless(n, 0.5235987755982988, 2);
  }
}

// Abutting and intersecting surfaces resolve per sample: two triangles crossing in depth split
// each pixel on the intersection line between their colours.
TEST(AntiAlias, IntersectingTrianglesResolvePerSample) {
  const int w = 32, h = 32;
  DrawPackets p;
  // Red tilts from near (left) to far (right), green the other way: they cross at x = 16.5.
  auto quad = [&](float zLeft, float zRight, float r, float g) {
    addTriangle(p, pixelVertex(-4, -4, w, h, zLeft, 1, r, g, 0),
                pixelVertex(37, -4, w, h, zRight, 1, r, g, 0),
                pixelVertex(-4, 40, w, h, zLeft, 1, r, g, 0));
    addTriangle(p, pixelVertex(37, 40, w, h, zRight, 1, r, g, 0),
                pixelVertex(-4, 40, w, h, zLeft, 1, r, g, 0),
                pixelVertex(37, -4, w, h, zRight, 1, r, g, 0));
  };
  quad(0.2f, 0.8f, 1, 0);
  quad(0.8f, 0.2f, 0, 1);
  const test::Frame f = test::renderQuadtree(p, aaSettings(w, h, 16));
  EXPECT_TRUE(f == test::renderReference(p, aaSettings(w, h, 16)));
  // Column 16 is split by the intersection: half red, half green; its neighbours are pure.
  for (int y = 0; y < h; ++y) {
    EXPECT_EQ(f.resolved(15, y, 0), 65535) << y;
    EXPECT_EQ(f.resolved(17, y, 1), 65535) << y;
    const int red = f.resolved(16, y, 0), green = f.resolved(16, y, 1);
    EXPECT_NEAR(red, 32768, 65535 / 8) << y;
    EXPECT_NEAR(red + green, 65535, 2) << y;
  }
}

}  // namespace
}  // namespace sv
