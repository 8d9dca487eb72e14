// Seed 002's segment pipeline (SPEC §10; issue 35) for a frame's draw packets: no frame buffer of
// depths — each scan line's segments, in priority order, sent as segment words through a FIFO to a
// sorter that sorts them by overwrite into RUN codes (segments/x_sort.h); then each run's pixels
// shaded along it, the video channel's filters (the recipient–donor 1×1 filter, the 3×3 triangle
// filter, SPEC §5) and the gamma table.
//
// Two stages, as the seed's channel: the geometry stage (the lines' active triangles, their
// segments) and the sorter stage (X-sort into RUN codes), on two threads with a bounded ring of
// segment words between them — or on one thread, a line at a time, when the pool has one. The
// pixels of the sorted lines are then shaded in bands of rows on all the pool's threads (shading
// them in the sorter stage left it the slower of the two: docs/performance.md). The channel's
// overload protection (segments/channel_clock.h) decides on a model clock counted in segment
// words which lines are repeated, so the image is the same bytes for any thread count.
//
// Visibility is priority: the packets' triangle order, first in front — the order the tile
// pipeline's priority masking draws in (buildDrawPackets under Hsr::priority), so at one sample per
// pixel the two pipelines show the same triangle at every pixel (tests/render/segment_test.cpp).
// The colour is the tile kernel's perspective-correct Gouraud colour, the same float operations,
// so without the filters the images agree byte for byte.
#pragma once

#include <cstdint>
#include <vector>

#include "core/thread_pool.h"
#include "geometry/setup.h"
#include "output/resolve.h"
#include "render/draw_packets.h"
#include "segments/channel_clock.h"
#include "segments/x_sort.h"
#include "synthvis/frame_stats.h"

namespace sv::render {

struct SegmentSettings {
  int width = 0, height = 0;
  float clearColor[3] = {0, 0, 0};  // linear
  segments::ChannelTiming timing;   // the overload protection's model clock
  // Two fields a frame, the even lines then the odd ones, each through the channel on its own
  // clock; a repeated line of the second field is the mean of its neighbours in the first.
  bool interlaced = false;
  // Fog (SPEC §8, seed 002): C = C_c·2^(−β·r) + C_F·(1 − 2^(−β·r)) per pixel of a surface, r the
  // eye's distance to the pixel's point — its eye depth w (1 ÷ the 1/w plane) times the length of
  // its ray at unit depth through the view window tanLeft … tanTop (a perspective projection's
  // clip w is the eye depth).
  bool fog = false;
  float fogColor[3] = {0, 0, 0};  // linear
  float fogBeta = 0;
  double tanLeft = -1, tanRight = 1, tanBottom = -1, tanTop = 1;
  bool donor = false;  // the recipient–donor 1×1 filter (segments/recipient_donor.h)
  bool tent = false;   // the 3×3 triangle filter [1 2 1]ᵀ[1 2 1]/16 after it
};

class SegmentRenderer {
 public:
  // The frame of `packets` (vertex colours: the Gouraud shading of the tile pipeline's
  // ShadeMode::gouraud) into `image` (sized here), through `gamma`, on `pool`'s threads; adds the
  // triangles' outcomes (culled as the tile pipeline culls them), the segments, runs and repeated
  // lines, and the times (setup; the lines and filters as rasterMs) to `stats`.
  void render(const DrawPackets& packets, const SegmentSettings& settings,
              const output::GammaTable& gamma, core::ThreadPool& pool, Image& image,
              FrameStats& stats);

  // One segment word of the FIFO: a segment (the drawn triangle's number and its pixels [xl, xr))
  // or, with `segment` kEndOfLine or kRepeatLine, the end of a line or the line-repeat flag.
  struct Word {
    uint32_t segment;
    int32_t xl, xr;
  };
  static constexpr uint32_t kEndOfLine = ~0u, kRepeatLine = ~0u - 1;

 private:
  struct Field;
  void runField(const Field& field, core::ThreadPool& pool, FrameStats& stats);
  void produceLine(const Field& field, int line, std::vector<Word>& words);
  void finishLine(int y, const segments::XSorter& sorter, std::vector<segments::Run>& runs,
                  FrameStats& stats);
  void shadeRow(const SegmentSettings& settings, bool linear, uint32_t background, int y,
                std::vector<uint16_t>& buffer);
  void repeatLine(const Field& field, int y);

  std::vector<geometry::TriangleSetup> all_;     // every packet triangle's record
  std::vector<uint8_t> outcome_;                 // per packet triangle: its SetupOutcome
  std::vector<geometry::TriangleSetup> setups_;  // the drawn triangles', in priority order
  std::vector<uint32_t> firstRow_;               // per row: its first starting triangle in byRow_
  std::vector<uint32_t> byRow_;                  // drawn triangles by first row, priority within
  // The geometry stage's active list (drawn triangles reaching the line, in priority order) and the
  // last row whose starting triangles it has taken in.
  struct Active {
    uint32_t number;  // the drawn triangle's
    int32_t lastRow;  // its maxY, kept here: the list is filtered every row
  };
  std::vector<Active> active_, incoming_, merged_;
  int mergedRow_ = -1;
  // The sorter stage's output: each row's RUN codes, [begin, end) in runStore_ (kRepeated: the
  // line is repeated), shaded once the fields are sorted.
  struct RowRuns {
    uint32_t begin = 0, end = 0;
  };
  static constexpr uint32_t kRepeated = ~0u;
  std::vector<RowRuns> rowRuns_;
  std::vector<std::vector<uint16_t>> rowBuffers_;  // per worker: a row's codes before the gamma table
  std::vector<segments::Run> runStore_;
  // With a filter: the frame in linear light as the sorter left it, the triangle visible at each
  // pixel (for the recipient–donor filter: the drawn triangle's number, the background's m, a
  // repeated line's m + 1), and the donor-filtered frame.
  output::LinearImage linear_, filtered_;
  std::vector<uint32_t> visible_;
  Image* image_ = nullptr;
  const output::GammaTable* gamma_ = nullptr;
  uint16_t clear_[3] = {};
};

}  // namespace sv::render
