// Based on: SPEC §10 (seed 002: segments of each scan line in priority order, the priority X-sort
// by overwrite, RUN codes, per-pixel interpolation along the run, the gamma tables), §8 (Gouraud
// colour), §2 (the perspective-correct colour as colour/w ÷ 1/w, as the tile kernel computes it).
#include "render/segment_renderer.h"

#include <algorithm>
#include <cmath>

#include "core/timing.h"
#include "segments/segments.h"

namespace sv::render {
namespace {

// 0 … 1 to a 16-bit code, rounded to nearest even as the kernel's magic-number conversion does;
// NaN to 0, as its Max(v, 0).
uint16_t unitToCode(float v) {
  const float c = std::min(std::max(0.0f, v), 1.0f);
  return uint16_t(std::nearbyint(c * 65535.0f));
}

// Rows per task: a band's sorter and active list are its own.
constexpr int kBand = 16;

}  // namespace

void SegmentRenderer::render(const DrawPackets& packets, const SegmentSettings& s,
                             const output::GammaTable& gamma, core::ThreadPool& pool, Image& image,
                             FrameStats& stats) {
  const auto t0 = core::Clock::now();
  output::prepareImage(s.width, s.height, image);
  geometry::Viewport vp;
  vp.width = s.width;
  vp.height = s.height;
  // Setup, in parallel chunks, every triangle with its call's culling: the tile pipeline's records.
  const size_t n = packets.indices.size() / 3;
  all_.resize(n);
  outcome_.resize(n);
  constexpr size_t kChunk = 4096;
  pool.parallelFor((n + kChunk - 1) / kChunk, [&](size_t c, int) {
    const size_t end = std::min(n, (c + 1) * kChunk);
    size_t call = 0;
    for (size_t tri = c * kChunk; tri < end; ++tri) {
      while (call < packets.calls.size() &&
             tri >= size_t(packets.calls[call].firstTriangle) + packets.calls[call].triangleCount)
        ++call;
      const geometry::CullMode cull =
          call < packets.calls.size() ? packets.calls[call].cull : geometry::CullMode::none;
      const uint32_t* i = &packets.indices[tri * 3];
      outcome_[tri] =
          uint8_t(geometry::setupTriangle(packets.vertices[i[0]], packets.vertices[i[1]],
                                          packets.vertices[i[2]], vp, cull, all_[tri]));
    }
  });
  setups_.clear();
  uint64_t counts[5] = {};
  for (size_t tri = 0; tri < n; ++tri) {
    ++counts[outcome_[tri]];
    if (outcome_[tri] == uint8_t(geometry::SetupOutcome::drawn)) setups_.push_back(all_[tri]);
  }
  stats.trianglesIn += n;
  stats.drawn += counts[int(geometry::SetupOutcome::drawn)];
  stats.culledFacing += counts[int(geometry::SetupOutcome::culledFacing)];
  stats.culledOutside += counts[int(geometry::SetupOutcome::culledOutside)];
  stats.culledDegenerate += counts[int(geometry::SetupOutcome::culledDegenerate)];
  stats.culledInvalid += counts[int(geometry::SetupOutcome::culledInvalid)];
  // The drawn triangles bucketed by their first row, priority order kept within a row.
  const size_t m = setups_.size();
  firstRow_.assign(size_t(s.height) + 1, 0);
  for (const geometry::TriangleSetup& t : setups_) ++firstRow_[size_t(t.minY) + 1];
  for (int y = 0; y < s.height; ++y) firstRow_[size_t(y) + 1] += firstRow_[size_t(y)];
  byRow_.resize(m);
  {
    std::vector<uint32_t> next(firstRow_.begin(), firstRow_.end() - 1);
    for (uint32_t k = 0; k < m; ++k) byRow_[next[size_t(setups_[k].minY)]++] = k;
  }
  stats.setupMs += core::msSince(t0);

  const auto t1 = core::Clock::now();
  uint16_t clear[3];
  for (int c = 0; c < 3; ++c)
    clear[c] = uint16_t(std::lround(std::clamp(s.clearColor[c], 0.0f, 1.0f) * 65535.0f));
  const uint32_t background = uint32_t(m);  // no triangle's number
  const int bands = (s.height + kBand - 1) / kBand;
  struct Counts {
    uint64_t segments = 0, runs = 0;
  };
  std::vector<Counts> bandCounts(static_cast<size_t>(bands));
  pool.parallelFor(size_t(bands), [&](size_t band, int) {
    const int y0 = int(band) * kBand, y1 = std::min(s.height, y0 + kBand);
    segments::XSorter sorter(s.width);
    std::vector<segments::Run> runs;
    // The triangles that reach row y0 but start above it, then those starting in each row: the
    // active list, in priority order (ascending number).
    std::vector<uint32_t> active, merged;
    for (uint32_t k = 0; k < firstRow_[size_t(y0)]; ++k)
      if (setups_[byRow_[k]].maxY >= y0) active.push_back(byRow_[k]);
    std::sort(active.begin(), active.end());
    Counts& st = bandCounts[band];
    for (int y = y0; y < y1; ++y) {
      const auto first = byRow_.begin() + firstRow_[size_t(y)];
      const auto last = byRow_.begin() + firstRow_[size_t(y) + 1];
      merged.clear();
      std::merge(active.begin(), active.end(), first, last, std::back_inserter(merged));
      active.clear();
      for (uint32_t k : merged)
        if (setups_[k].maxY >= y) active.push_back(k);
      // Increasing priority: the last triangle first, so the first one's segment is written last.
      sorter.clear(background);
      for (auto it = active.rbegin(); it != active.rend(); ++it) {
        const segments::Segment seg = segments::segmentOf(setups_[*it], y, s.width);
        if (seg.empty()) continue;
        sorter.add(*it, seg.xl, seg.xr);
        ++st.segments;
      }
      sorter.runs(runs);
      st.runs += runs.size();
      uint8_t* row = image.pixel(0, y);
      for (size_t r = 0; r < runs.size(); ++r) {
        const int xa = runs[r].x, xb = r + 1 < runs.size() ? runs[r + 1].x : s.width;
        if (runs[r].segment == background) {
          for (int x = xa; x < xb; ++x)
            for (int c = 0; c < 3; ++c) row[3 * x + c] = gamma.table[clear[c]];
          continue;
        }
        // Along the run: colour/w and 1/w at each pixel centre, the colour their ratio.
        const geometry::TriangleSetup& t = setups_[runs[r].segment];
        const geometry::Plane* planes[3] = {&t.red, &t.green, &t.blue};
        for (int x = xa; x < xb; ++x) {
          const float w = 1.0f / geometry::planeAtPixel(t.invW, x, y, t.minX, t.minY);
          for (int c = 0; c < 3; ++c)
            row[3 * x + c] = gamma.table[unitToCode(
                geometry::planeAtPixel(*planes[c], x, y, t.minX, t.minY) * w)];
        }
      }
    }
  });
  for (const Counts& b : bandCounts) {
    stats.segments += b.segments;
    stats.segmentRuns += b.runs;
  }
  stats.rasterMs += core::msSince(t1);
}

}  // namespace sv::render
