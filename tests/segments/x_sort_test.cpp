// The priority X-sort (segments/x_sort.h): against a painter's algorithm on random segment sets —
// the same visible segment at every X — with the RUN codes exactly the change points; and on a
// frame's triangles, against the tile pipeline's priority masking at one sample per pixel.
#include "segments/x_sort.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "segments/segments.h"
#include "support/raster_harness.h"

namespace sv {
namespace {

TEST(XSort, AgreesWithAPaintersAlgorithmAndItsRunsAreTheChangePoints) {
  std::mt19937 rng(11);
  int runsChecked = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const int width = 1 + int(rng() % 300);
    const int count = int(rng() % 40);
    segments::XSorter sorter(width);
    std::vector<uint32_t> painted(size_t(width), 7);  // the background, number 7
    sorter.clear(7);
    for (int k = 0; k < count; ++k) {
      // Ends anywhere from left of the line to right of it, empty ones included.
      int a = int(rng() % uint32_t(width + 20)) - 10, b = int(rng() % uint32_t(width + 20)) - 10;
      if (rng() % 8 == 0) b = a;
      if (a > b) std::swap(a, b);
      const uint32_t number = 100 + uint32_t(k);
      sorter.add(number, a, b);
      for (int x = std::max(a, 0); x < std::min(b, width); ++x) painted[size_t(x)] = number;
    }
    for (int x = 0; x < width; ++x)
      ASSERT_EQ(sorter.at(x), painted[size_t(x)]) << trial << " " << x;
    std::vector<segments::Run> runs;
    sorter.runs(runs);
    std::vector<segments::Run> changes{{0, painted[0]}};
    for (int x = 1; x < width; ++x)
      if (painted[size_t(x)] != painted[size_t(x - 1)]) changes.push_back({x, painted[size_t(x)]});
    ASSERT_EQ(runs.size(), changes.size()) << trial;
    for (size_t i = 0; i < runs.size(); ++i) {
      EXPECT_EQ(runs[i].x, changes[i].x) << trial;
      EXPECT_EQ(runs[i].segment, changes[i].segment) << trial;
    }
    runsChecked += int(runs.size());
  }
  EXPECT_GT(runsChecked, 1500);
}

TEST(XSort, OfAFramesSegmentsShowsWhatTheTilePipelinesPriorityMaskingShows) {
  // A frame's triangles, each in a colour that names it, drawn by the tile pipeline under priority
  // masking (the packets' order is priority, first in front) at one sample; the segments of every
  // row sorted in increasing priority (last packet first): the same triangle at every pixel.
  const int w = 190, h = 140;
  render::DrawPackets p = test::randomScene(w, h, 150, 5, false);
  const uint32_t n = uint32_t(p.indices.size() / 3);
  ASSERT_LT(n * 256, 65535u);
  // Flat colours, 256 codes apart, so the 16-bit value names the triangle despite rounding.
  for (uint32_t tri = 0; tri < n; ++tri)
    for (int v = 0; v < 3; ++v) {
      geometry::ClipVertex& c = p.vertices[p.indices[tri * 3 + size_t(v)]];
      c.r = float((tri + 1) * 256) / 65535.0f, c.g = c.b = 0;
    }
  render::FrameSettings s;
  s.width = w;
  s.height = h;
  s.masking = raster::Masking::priority;
  const test::Frame frame = test::renderQuadtree(p, s);
  geometry::Viewport vp;
  vp.width = w;
  vp.height = h;
  std::vector<geometry::TriangleSetup> setups(n);
  std::vector<bool> drawn(n);
  size_t call = 0;
  for (uint32_t tri = 0; tri < n; ++tri) {
    while (call < p.calls.size() &&
           tri >= p.calls[call].firstTriangle + p.calls[call].triangleCount)
      ++call;
    const uint32_t* i = &p.indices[size_t(tri) * 3];
    drawn[tri] = geometry::setupTriangle(
                     p.vertices[i[0]], p.vertices[i[1]], p.vertices[i[2]], vp,
                     call < p.calls.size() ? p.calls[call].cull : geometry::CullMode::none,
                     setups[tri]) == geometry::SetupOutcome::drawn;
  }
  const uint32_t background = n;  // a number no triangle has
  segments::XSorter sorter(w);
  int covered = 0;
  for (int y = 0; y < h; ++y) {
    sorter.clear(background);
    for (uint32_t tri = n; tri-- > 0;) {
      if (!drawn[tri]) continue;
      const segments::Segment seg = segments::segmentOf(setups[tri], y, w);
      sorter.add(tri, seg.xl, seg.xr);
    }
    for (int x = 0; x < w; ++x) {
      const uint32_t visible = sorter.at(x);
      const int code = frame.channel(x, y, 0);
      const uint32_t shown = code == 0 ? background : uint32_t((code + 128) / 256 - 1);
      ASSERT_EQ(visible, shown) << x << "," << y;
      covered += visible != background;
    }
  }
  EXPECT_GT(covered, w * h / 2);
}

}  // namespace
}  // namespace sv
