#include "render/frame_renderer.h"

#include <algorithm>
#include <chrono>

namespace sv::render {
namespace {

// Triangles are processed in batches (bounded memory for the setup records, and bins that stay in
// cache), each batch set up in fixed-size chunks. Both sizes are constants, not functions of the
// thread count, so the draw order inside every tile — and so the image — never depends on threads.
constexpr uint32_t kBatchTriangles = 1u << 14;
constexpr uint32_t kChunkTriangles = 1u << 10;
constexpr int kChunksPerBatch = kBatchTriangles / kChunkTriangles;

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

struct SetupCounts {
  uint64_t facing = 0, outside = 0, degenerate = 0, invalid = 0, drawn = 0;
};

// For triangle number `tri` (global), the draw call it belongs to, found by a forward scan.
struct CallCursor {
  const std::vector<DrawCall>& calls;
  size_t index = 0;
  const DrawCall* find(uint32_t tri) {
    while (index < calls.size() && tri >= calls[index].firstTriangle + calls[index].triangleCount)
      ++index;
    return index < calls.size() && tri >= calls[index].firstTriangle ? &calls[index] : nullptr;
  }
};

}  // namespace

void FrameRenderer::render(const DrawPackets& packets, const FrameSettings& settings,
                           FrameStats& stats) {
  fb_.resize(settings.width, settings.height);
  const geometry::Viewport viewport{settings.width, settings.height};
  const uint32_t triangleCount = static_cast<uint32_t>(packets.indices.size() / 3);
  const int tiles = fb_.tileCount();
  uint16_t clear16[3];
  for (int ch = 0; ch < 3; ++ch)
    clear16[ch] = static_cast<uint16_t>(
        std::lround(std::clamp(settings.clearColor[ch], 0.0f, 1.0f) * 65535.0f));
  if (settings.shade == raster::ShadeMode::overdraw) std::fill_n(clear16, 3, uint16_t(0));

  // Stage 3a: snap every vertex once (shared vertices then agree in all their triangles).
  auto t0 = Clock::now();
  constexpr size_t kSnapChunk = 1 << 14;
  screen_.resize(packets.vertices.size());
  pool_.parallelFor((packets.vertices.size() + kSnapChunk - 1) / kSnapChunk, [&](size_t c, int) {
    const size_t end = std::min(packets.vertices.size(), (c + 1) * kSnapChunk);
    for (size_t i = c * kSnapChunk; i < end; ++i)
      screen_[i] = geometry::snapVertex(packets.vertices[i], viewport);
  });
  stats.setupMs += msSince(t0);

  setups_.resize(kBatchTriangles);
  tileStats_.assign(size_t(tiles), raster::RasterStats{});
  std::vector<SetupCounts> counts(kChunksPerBatch);
  stats.trianglesIn += triangleCount;

  // Always run at least one (empty) batch, so the tiles get cleared.
  for (uint32_t batch = 0; batch == 0 || batch < triangleCount; batch += kBatchTriangles) {
    const uint32_t batchEnd = std::min(triangleCount, batch + kBatchTriangles);
    const int chunks = int((batchEnd - batch + kChunkTriangles - 1) / kChunkTriangles);

    // Stage 3b: setup and binning, chunk by chunk.
    t0 = Clock::now();
    binner_.reset(std::max(chunks, 1), fb_.tilesX(), fb_.tilesY());
    pool_.parallelFor(size_t(chunks), [&](size_t chunk, int) {
      SetupCounts c;
      const uint32_t begin = batch + uint32_t(chunk) * kChunkTriangles;
      const uint32_t end = std::min(batchEnd, begin + kChunkTriangles);
      CallCursor cursor{packets.calls};
      for (uint32_t tri = begin; tri < end; ++tri) {
        const DrawCall* call = cursor.find(tri);
        const uint32_t* idx = &packets.indices[size_t(tri) * 3];
        geometry::TriangleSetup& s = setups_[tri - batch];
        const geometry::ClipVertex* v[3] = {&packets.vertices[idx[0]], &packets.vertices[idx[1]],
                                            &packets.vertices[idx[2]]};
        const geometry::ScreenVertex* sv[3] = {&screen_[idx[0]], &screen_[idx[1]], &screen_[idx[2]]};
        switch (geometry::setupTriangle(v, sv, viewport,
                                        call ? call->cull : geometry::CullMode::none, s)) {
          case geometry::SetupOutcome::drawn:
            ++c.drawn;
            binner_.bin(int(chunk), tri - batch, s);
            break;
          case geometry::SetupOutcome::culledFacing: ++c.facing; break;
          case geometry::SetupOutcome::culledOutside: ++c.outside; break;
          case geometry::SetupOutcome::culledDegenerate: ++c.degenerate; break;
          case geometry::SetupOutcome::culledInvalid: ++c.invalid; break;
        }
      }
      counts[chunk] = c;
    });
    for (int i = 0; i < chunks; ++i) {
      stats.drawn += counts[i].drawn;
      stats.culledFacing += counts[i].facing;
      stats.culledOutside += counts[i].outside;
      stats.culledDegenerate += counts[i].degenerate;
      stats.culledInvalid += counts[i].invalid;
    }
    stats.setupMs += msSince(t0);

    // Stage 4: the tiles, each drawing its lists in chunk order.
    t0 = Clock::now();
    const int lists = binner_.chunkCount();
    pool_.parallelFor(size_t(tiles), [&](size_t tile, int) {
      const uint32_t* listPtr[kChunksPerBatch];
      uint32_t listSize[kChunksPerBatch];
      for (int c = 0; c < lists; ++c) {
        const auto& l = binner_.list(c, int(tile));
        listPtr[c] = l.data();
        listSize[c] = uint32_t(l.size());
      }
      raster::TileWork w;
      w.tileX = int(tile) % fb_.tilesX();
      w.tileY = int(tile) / fb_.tilesX();
      w.depth = fb_.tileDepth(int(tile));
      w.color = fb_.tileColor(int(tile));
      w.clear = batch == 0;
      std::copy_n(clear16, 3, w.clearColor);
      w.setups = setups_.data();
      w.lists = listPtr;
      w.listSizes = listSize;
      w.listCount = lists;
      w.shade = settings.shade;
      raster::rasterizeTile(w, tileStats_[tile]);
    });
    stats.rasterMs += msSince(t0);
  }

  raster::RasterStats total;
  for (const auto& s : tileStats_) total.add(s);
  for (int i = 0; i < raster::kStatLevels; ++i) stats.windows[i] += total.windows[i];
  stats.fullWindows += total.fullWindows;
  stats.partialBlocks += total.partialBlocks;
  stats.fragments += total.fragments;
}

}  // namespace sv::render
