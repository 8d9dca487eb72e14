// The segment pipeline (render/segment_renderer.h) against the tile pipeline: a frame's packets
// drawn by both — the tiles under priority masking at one sample, resolved through the same gamma
// table — give the same bytes, for ordinary and wild triangles (behind the eye, beyond the near
// and far planes, huge), and any thread count gives the same image.
#include <gtest/gtest.h>

#include "output/resolve.h"
#include "render/segment_renderer.h"
#include "support/raster_harness.h"

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

}  // namespace
}  // namespace sv
