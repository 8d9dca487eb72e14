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

namespace sv::render {

struct SegmentSettings {
  int width = 0, height = 0;
  float clearColor[3] = {0, 0, 0};  // linear
};

struct SegmentStats {
  uint64_t triangles = 0;  // set up and drawn (the rest culled as the tile pipeline culls them)
  uint64_t segments = 0;   // non-empty segments sorted
  uint64_t runs = 0;       // RUN codes read (a run per change of the visible segment)
  double setupMs = 0, linesMs = 0;
};

class SegmentRenderer {
 public:
  explicit SegmentRenderer(int threads) : pool_(threads) {}

  // The frame of `packets` (vertex colours: the Gouraud shading of the tile pipeline's
  // ShadeMode::gouraud) into `image` (sized here), through `gamma`.
  void render(const DrawPackets& packets, const SegmentSettings& settings,
              const output::GammaTable& gamma, Image& image, SegmentStats& stats);

  core::ThreadPool& pool() { return pool_; }

 private:
  core::ThreadPool pool_;
  std::vector<geometry::TriangleSetup> setups_;  // the drawn triangles', in priority order
  std::vector<uint8_t> drawn_;                   // per packet triangle: set up and drawn
  std::vector<uint32_t> firstRow_;               // per row: its first starting triangle in byRow_
  std::vector<uint32_t> byRow_;                  // drawn triangles by first row, priority within
};

}  // namespace sv::render
