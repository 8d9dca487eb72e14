// Seed 002's segment pipeline (SPEC §10; issue 35) for a frame's draw packets: no frame buffer of
// depths — each scan line's segments, in priority order, sorted by overwrite into RUN codes
// (segments/x_sort.h), then each run's pixels shaded along it and put through the gamma table.
//
// Visibility is priority: the packets' triangle order, first in front — the order the tile
// pipeline's priority masking draws in (buildDrawPackets under Hsr::priority), so at one sample per
// pixel the two pipelines show the same triangle at every pixel (tests/render/segment_test.cpp).
// The colour is the tile kernel's perspective-correct Gouraud colour, the same float operations,
// so the images agree byte for byte. Rows go in bands to the pool's threads, each band with its
// own sorter: the same bytes for any thread count.
#pragma once

#include <cstdint>
#include <vector>

#include "core/thread_pool.h"
#include "geometry/setup.h"
#include "output/resolve.h"
#include "render/draw_packets.h"
#include "segments/x_sort.h"
#include "synthvis/frame_stats.h"

namespace sv::render {

struct SegmentSettings {
  int width = 0, height = 0;
  float clearColor[3] = {0, 0, 0};  // linear
};

class SegmentRenderer {
 public:
  // The frame of `packets` (vertex colours: the Gouraud shading of the tile pipeline's
  // ShadeMode::gouraud) into `image` (sized here), through `gamma`, on `pool`'s threads; adds the
  // triangles' outcomes (culled as the tile pipeline culls them), the segments and runs, and the
  // times (setup; the lines as rasterMs) to `stats`.
  void render(const DrawPackets& packets, const SegmentSettings& settings,
              const output::GammaTable& gamma, core::ThreadPool& pool, Image& image,
              FrameStats& stats);

 private:
  std::vector<geometry::TriangleSetup> all_;     // every packet triangle's record
  std::vector<uint8_t> outcome_;                 // per packet triangle: its SetupOutcome
  std::vector<geometry::TriangleSetup> setups_;  // the drawn triangles', in priority order
  std::vector<uint32_t> firstRow_;               // per row: its first starting triangle in byRow_
  std::vector<uint32_t> byRow_;                  // drawn triangles by first row, priority within
};

}  // namespace sv::render
