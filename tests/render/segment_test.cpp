// The segment pipeline (render/segment_renderer.h) against the tile pipeline: a frame's packets
// drawn by both — the tiles under priority masking at one sample, resolved through the same gamma
// table — give the same bytes, for ordinary and wild triangles (behind the eye, beyond the near
// and far planes, huge), and any thread count gives the same image; with the 3×3 triangle filter
// too. The channel: lines repeated under a throttled geometry stage, the frame still complete;
// interlaced fields; the recipient–donor filter on a single edge against its area formula.
#include <gtest/gtest.h>

#include "output/resolve.h"
#include "render/segment_renderer.h"
#include "support/raster_harness.h"
#include "segments/recipient_donor.h"

#include <cmath>

namespace sv {
namespace {

TEST(SegmentPipeline, DrawsTheTilePipelinesPriorityMaskedImageByteForByte) {
  const output::GammaTable gamma = output::GammaTable::srgb();
  for (bool wild : {false, true})
    for (unsigned seed : {21u, 22u}) {
      const int w = 230, h = 170;
      const render::DrawPackets p = test::randomScene(w, h, 300, seed, wild);
      render::FrameSettings fs;
      fs.width = w;
      fs.height = h;
      fs.clearColor[0] = 0.1f;
      fs.clearColor[2] = 0.3f;
      fs.masking = raster::Masking::priority;
      const test::Frame tiles = test::renderQuadtree(p, fs);
      render::SegmentSettings ss;
      ss.width = w;
      ss.height = h;
      std::copy_n(fs.clearColor, 3, ss.clearColor);
      std::vector<Image> images;
      FrameStats stats;
      for (int threads : {1, 2, 5}) {
        render::SegmentRenderer r;
        core::ThreadPool pool(threads);
        images.emplace_back();
        stats = {};
        r.render(p, ss, gamma, pool, images.back(), stats);
      }
      int differing = 0, drawn = 0;
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
          for (int c = 0; c < 3; ++c) {
            differing += images[0].pixel(x, y)[c] != gamma.table[tiles.channel(x, y, c)];
            drawn += tiles.depth[size_t(y) * w + x] < 1.0f;
          }
      EXPECT_EQ(differing, 0) << "seed " << seed << (wild ? " wild" : "");
      EXPECT_GT(drawn, w * h);  // most pixels covered (counted once per channel)
      EXPECT_GT(stats.segments, 5000u);
      EXPECT_GT(stats.segmentRuns, uint64_t(h));
      EXPECT_EQ(stats.trianglesIn, 300u);
      EXPECT_GT(stats.drawn, 100u);
      EXPECT_EQ(images[0].rgb, images[1].rgb);
      EXPECT_EQ(images[0].rgb, images[2].rgb);
    }
}


// The segment pipeline's settings for a w × h frame, and the tile pipeline's under priority
// masking — the two drawn side by side.
render::SegmentSettings segmentSettings(int w, int h) {
  render::SegmentSettings ss;
  ss.width = w;
  ss.height = h;
  return ss;
}
render::FrameSettings prioritySettings(int w, int h) {
  render::FrameSettings fs;
  fs.width = w;
  fs.height = h;
  fs.masking = raster::Masking::priority;
  return fs;
}

// Renders `p` with `ss` on 1, 2 and 5 threads; expects the same image from all; returns it.
Image renderAll(const render::DrawPackets& p, const render::SegmentSettings& ss,
                const output::GammaTable& gamma, FrameStats& stats) {
  std::vector<Image> images;
  for (int threads : {1, 2, 5}) {
    render::SegmentRenderer r;
    core::ThreadPool pool(threads);
    images.emplace_back();
    stats = {};
    r.render(p, ss, gamma, pool, images.back(), stats);
  }
  EXPECT_EQ(images[0].rgb, images[1].rgb);
  EXPECT_EQ(images[0].rgb, images[2].rgb);
  return images[0];
}

bool sameRow(const Image& a, int ya, const Image& b, int yb) {
  return std::equal(a.pixel(0, ya), a.pixel(0, ya) + 3 * a.width, b.pixel(0, yb));
}

TEST(SegmentPipeline, WithTheTentFilterDrawsTheTilePipelinesFilteredImage) {
  const output::GammaTable gamma = output::GammaTable::srgb();
  const int w = 200, h = 120;
  const render::DrawPackets p = test::randomScene(w, h, 300, 31, false);
  const test::Frame tiles = test::renderQuadtree(p, prioritySettings(w, h));
  output::LinearImage linear;
  linear.resize(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        linear.rgb[(size_t(y) * w + size_t(x)) * 3 + size_t(c)] = tiles.channel(x, y, c);
  Image expected;
  output::prepareImage(w, h, expected);
  output::tentFilterRows(linear, gamma, 0, h, expected);
  render::SegmentSettings ss = segmentSettings(w, h);
  ss.tent = true;
  FrameStats stats;
  EXPECT_EQ(renderAll(p, ss, gamma, stats).rgb, expected.rgb);
}

TEST(SegmentPipeline, AThrottledGeometryStageRepeatsLinesAndTheFrameIsComplete) {
  // Under a rate below the frame's mean segment words per line, some lines are repeated: each row
  // is the unthrottled frame's row, or (progressive) a copy of the row above it — or (interlaced,
  // second field) the mean of its neighbours. The same lines for any thread count.
  const output::GammaTable gamma = output::GammaTable::srgb();
  const int w = 240, h = 160;
  const render::DrawPackets p = test::randomScene(w, h, 600, 41, false);
  render::SegmentSettings ss = segmentSettings(w, h);
  ss.clearColor[1] = 0.2f;
  FrameStats full;
  const Image exact = renderAll(p, ss, gamma, full);
  EXPECT_EQ(full.repeatedLines, 0u);
  const double mean = double(full.segments + uint64_t(h)) / h;  // words a line, ends included
  ss.interlaced = true;
  FrameStats fields;
  EXPECT_EQ(renderAll(p, ss, gamma, fields).rgb, exact.rgb);  // unthrottled: the same frame
  for (bool interlaced : {false, true}) {
    ss.interlaced = interlaced;
    ss.timing.wordsPerLine = int64_t(mean * 0.7);
    FrameStats stats;
    const Image img = renderAll(p, ss, gamma, stats);
    EXPECT_GT(stats.repeatedLines, uint64_t(h) / 10) << interlaced;
    EXPECT_LT(stats.repeatedLines, uint64_t(h) * 3 / 4) << interlaced;
    uint64_t repeats = 0;
    for (int y = 0; y < h; ++y) {
      if (sameRow(img, y, exact, y)) continue;
      ++repeats;
      if (!interlaced || y % 2 == 0) {
        const int above = y - (interlaced ? 2 : 1);
        if (above >= 0)
          EXPECT_TRUE(sameRow(img, y, img, above)) << interlaced << " row " << y;
        else
          EXPECT_EQ(img.pixel(0, y)[1], gamma.table[uint16_t(std::lround(0.2 * 65535))]);
      } else {
        const int below = y + 1 < h ? y + 1 : y - 1;
        for (int i = 0; i < 3 * w; ++i)
          EXPECT_EQ(img.pixel(0, y)[i],
                    (img.pixel(0, y - 1)[i] + img.pixel(0, below)[i] + 1) / 2)
              << "row " << y;
      }
    }
    // Rows that differ were repeated (a repeated row may happen to equal the exact one).
    EXPECT_LE(repeats, stats.repeatedLines) << interlaced;
    EXPECT_GT(repeats, stats.repeatedLines / 2) << interlaced;
  }
}

TEST(SegmentPipeline, TheRecipientDonorFilterWeighsABoundaryPixelByItsArea) {
  // A white triangle on black whose one edge crosses the raster, in linear output (gamma 1): every
  // pixel the edge crosses shows the area of it inside the edge — on the inside the triangle is
  // the recipient and black the donor across its edge, on the outside the background is the
  // recipient and the triangle, in front of it at a neighbour, the donor. (On the raster's border
  // a donor beyond it leaves the pixel whole: the border is not checked.)
  const output::GammaTable gamma = output::GammaTable::power(1.0);
  const int w = 96, h = 64;
  for (double angle : {0.1, 0.7, 1.3, 2.2, 3.9, 5.5}) {
    const double cx = 47.3, cy = 31.8, c = std::cos(angle), s = std::sin(angle);
    const double px = cx - 500 * c, py = cy - 500 * s, qx = cx + 500 * c, qy = cy + 500 * s;
    const double rx = cx - 500 * s, ry = cy + 500 * c;
    const auto clip = [&](double x, double y) {
      return geometry::ClipVertex{float(2 * x / w - 1), float(1 - 2 * y / h), 0.5f, 1, 1, 1, 1, 1};
    };
    render::DrawPackets p;
    test::addTriangle(p, clip(px, py), clip(qx, qy), clip(rx, ry));
    render::SegmentSettings ss = segmentSettings(w, h);
    ss.donor = true;
    FrameStats stats;
    const Image img = renderAll(p, ss, gamma, stats);
    // The inward unit normal (toward r).
    double nx = -(qy - py), ny = qx - px;
    const double len = std::hypot(nx, ny);
    nx /= len, ny /= len;
    if (nx * (rx - px) + ny * (ry - py) < 0) nx = -nx, ny = -ny;
    int boundary = 0;
    for (int y = 1; y + 1 < h; ++y)
      for (int x = 1; x + 1 < w; ++x) {
        const double d = nx * (x + 0.5 - px) + ny * (y + 0.5 - py);
        if (std::fabs(d) < 0.01) continue;  // a centre within snapping of the edge
        const double area = segments::halfPlaneArea(nx, ny, d);
        const int v = img.pixel(x, y)[0];
        EXPECT_NEAR(v, 255 * area, 2.0) << angle << " at " << x << "," << y;
        boundary += area > 0 && area < 1;
      }
    EXPECT_GT(boundary, 60) << angle;
  }
}

}  // namespace
}  // namespace sv
