// Segments cut from setup records (segments/segments.h): a row's segment holds exactly the pixel
// centres every edge function admits — the tile pipeline's point-sampled coverage — for ordinary
// and wild triangles (vertices behind the eye, beyond the near and far planes, huge); its ends lie
// where the edges cross the row's centre line.
#include "segments/segments.h"

#include <gtest/gtest.h>

#include <cmath>

#include "support/raster_harness.h"

namespace sv {
namespace {

TEST(Segments, HoldExactlyThePixelCentresTheTilePipelineCovers) {
  const int w = 200, h = 150;
  geometry::Viewport vp;
  vp.width = w;
  vp.height = h;
  int64_t covered = 0, rows = 0;
  for (bool wild : {false, true})
    for (unsigned seed : {3u, 4u}) {
      const render::DrawPackets p = test::randomScene(w, h, 120, seed, wild);
      for (size_t tri = 0; tri < p.indices.size() / 3; ++tri) {
        geometry::TriangleSetup t;
        const uint32_t* i = &p.indices[tri * 3];
        if (geometry::setupTriangle(p.vertices[i[0]], p.vertices[i[1]], p.vertices[i[2]], vp,
                                    geometry::CullMode::none, t) != geometry::SetupOutcome::drawn)
          continue;
        for (int y = -1; y <= h; ++y) {
          const segments::Segment s = segments::segmentOf(t, y, w);
          for (int x = 0; x < w; ++x) {
            bool inside = y >= 0 && y < h;
            for (int k = 0; k < t.edgeCount && inside; ++k) {
              const geometry::EdgeFunction& e = t.edges[k];
              inside = e.c + e.stepX() * x + e.stepY() * y >= 0;
            }
            ASSERT_EQ(inside, x >= s.xl && x < s.xr)
                << "seed " << seed << (wild ? " wild" : "") << " triangle " << tri << " row " << y
                << " x " << x << " segment [" << s.xl << ", " << s.xr << ")";
            covered += inside;
          }
          rows += !s.empty();
        }
      }
    }
  EXPECT_GT(covered, 100000);  // the scenes cover the raster several times over
  EXPECT_GT(rows, 5000);
}

TEST(Segments, EndsAreThePixelCentresInsideWhereTheEdgesCrossTheRow) {
  // A triangle with a vertical left edge at x = 10.25 and a right edge from (10.25, 2) to
  // (60.75, 102): on row y its span's ends are 10.25 and 10.25 + 0.505·(y + 0.5 − 2), to the
  // 1/256 pixel the vertices are snapped to; the segment holds the centres between them.
  const int w = 80, h = 110;
  render::DrawPackets p;
  test::addTriangle(p, test::pixelVertex(10.25, 2, w, h), test::pixelVertex(10.25, 102, w, h),
                    test::pixelVertex(60.75, 102, w, h));
  geometry::Viewport vp;
  vp.width = w;
  vp.height = h;
  geometry::TriangleSetup t;
  ASSERT_EQ(geometry::setupTriangle(p.vertices[0], p.vertices[1], p.vertices[2], vp,
                                    geometry::CullMode::none, t),
            geometry::SetupOutcome::drawn);
  int checked = 0;
  for (int y = 2; y < 102; ++y) {
    const segments::Segment s = segments::segmentOf(t, y, w);
    const double right = 10.25 + 0.505 * (y + 0.5 - 2);
    if (s.empty()) continue;
    // The centres inside: x + ½ ∈ [10.25, right).
    EXPECT_EQ(s.xl, 10);
    if (std::abs(right - 0.5 - std::round(right - 0.5)) > 1.0 / 128) {  // not a snapping tie
      EXPECT_EQ(s.xr - 1, int(std::ceil(right - 0.5)) - 1) << y;
    }
    ++checked;
  }
  EXPECT_GT(checked, 95);
}

}  // namespace
}  // namespace sv
