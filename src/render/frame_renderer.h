// One frame from clip-space packets to a filled frame buffer: setup and binning in parallel chunks,
// then the tiles in parallel (SPEC §1 stages 3–4, §3.4, §6).
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <vector>

#include "core/thread_pool.h"
#include "geometry/setup.h"
#include "raster/binner.h"
#include "raster/framebuffer.h"
#include "raster/rasterizer.h"
#include "render/draw_packets.h"
#include "synthvis/render.h"

namespace sv::render {

// The largest batch a frame uses (FrameSettings::batchTriangles is clamped to it).
inline constexpr uint32_t kMaxBatchTriangles = 1u << 24;

// Where a finished tile goes (FrameSettings::finishTile).
using TileSink =
    std::function<void(int tile, const float* depth, const uint16_t* color, const int32_t* sums)>;

struct FrameSettings {
  int width = 0, height = 0;
  float clearColor[3] = {0, 0, 0};  // linear
  raster::ShadeMode shade = raster::ShadeMode::gouraud;
  const shade::Environment* environment = nullptr;  // lights and fog, for ShadeMode::material
  // Samples per pixel: 1 (point sampling at centres) or 4, 8, 16, 64 (anti-aliasing with sub-pixel
  // masks, SPEC §5). finishTile then receives `samples` sample planes per block.
  int samples = 1;
  // Called once per tile, on the thread that drew it, right after the tile's last triangle, with
  // the tile's depth and colour (laid out as raster/framebuffer.h describes, `samples` per pixel),
  // or — when colour sums are used (`colorSums`) — its sums instead (then depth and colour hold
  // nothing; otherwise `sums` is nullptr). This is the only way out of the frame: the storage is
  // reused for the next tile as soon as the call returns.
  TileSink finishTile;
  // finishTile reads the tiles' depth. Without it, a frame with light points lets each tile's
  // depth go once the lights have kept what they need of it (raster::TilePass::seeTile) — it is
  // then drawn in a per-thread buffer that stays in the core's cache — and hands finishTile
  // nullptr for depth.
  bool depthToSink = true;
  // finishTile can take colour sums (it needs no more than each pixel's mean: a box resolve).
  // They are used when the frame allows — anti-aliased priority masking, every triangle opaque,
  // no pass besides the polygons, no occupancy view (raster::TileWork::sums) — and save writing,
  // clearing and summing N sample planes per pixel.
  bool colorSums = false;
  // Triangles per batch (every batch sets up its triangles, then walks the tiles). Frames of one
  // batch draw each tile in a small per-thread buffer that never leaves the core's cache; frames of
  // several keep a whole-frame buffer between batches. Tests lower it to exercise that path.
  uint32_t batchTriangles = 1u << 18;
  // Masking (raster::TileWork::masking): `priority` takes the packets' triangles in priority order,
  // nearest first.
  raster::Masking masking = raster::Masking::none;
  // The occupancy debug view (raster::TileWork::debugOccupancy).
  bool debugOccupancy = false;
  // The frame's passes besides the polygons (raster/tile_pass.h), in the order render composed
  // them: each prepared once, drawn into every tile where its stage says — surfaces and volumes
  // once the tile's opaque triangles are in, lights once the tiles around it are drawn too,
  // before finishTile — and its statistics added to the frame's.
  std::vector<raster::TilePass*> passes;
  // A frame shared by several processes (synthvis/tile_share.h): only this part's tiles are
  // drawn and handed to finishTile; setup and binning still see the whole frame.
  TileShare share;
};

class FrameRenderer {
 public:
  explicit FrameRenderer(int threads) : pool_(threads) {}

  // Draws `packets`, handing every finished tile (of this part, in a shared frame) to
  // settings.finishTile; adds to `stats`. Fails only when a shared frame's exchange does.
  Status render(const DrawPackets& packets, const FrameSettings& settings, FrameStats& stats);

  core::ThreadPool& pool() { return pool_; }

 private:
  // What one frame's batches share (render works it out once).
  struct Frame;
  // One batch of triangles [begin, end).
  struct Batch {
    uint32_t begin = 0, end = 0;
    int chunks = 0;
    bool first = true, last = true;
  };
  struct SetupCounts {
    uint64_t facing = 0, outside = 0, degenerate = 0, invalid = 0, occluded = 0, drawn = 0;
  };

  Frame frameOf(const DrawPackets& packets, const FrameSettings& settings) const;
  void prepareBuffers(const DrawPackets& packets, const Frame& f);
  void preparePasses(const FrameSettings& settings, const Frame& f);
  // Stage 3: setup and binning of the batch, chunk by chunk in parallel.
  void setUpBatch(const DrawPackets& packets, const FrameSettings& settings, const Frame& f,
                  const Batch& batch, FrameStats& stats);
  SetupCounts setUpChunk(const DrawPackets& packets, const FrameSettings& settings, const Frame& f,
                         const Batch& batch, int chunk, int worker);
  // Stage 4: the tiles in parallel, each drawing its lists in chunk order.
  void drawTiles(const FrameSettings& settings, const Frame& f, const Batch& batch);
  void drawTile(const FrameSettings& settings, const Frame& f, const Batch& batch, int tile,
                int worker);
  void finishTile(const FrameSettings& settings, int tile, float* depth, uint16_t* color,
                  int32_t* sums, int worker);
  // A frame with light points drawn as a wavefront (Frame::wavefront): tile `tile` is drawn and
  // seen; the tiles around it whose neighbourhood that completes get their lights and go to the
  // sink.
  void tileDrawn(const FrameSettings& settings, const Frame& f, int tile, int worker);
  // A buffer of the pool: the one `worker` gave back last (still in its core's cache), else
  // another's, else a new one.
  raster::FrameBuffer* takeTileBuffer(int samples, int worker);
  void giveTileBuffer(raster::FrameBuffer* buffer, int worker);
  void addTileStats(FrameStats& stats) const;

  core::ThreadPool pool_;
  raster::FrameBuffer fb_;  // the whole frame, in frames of several batches
  raster::Binner binner_;
  struct WorkerScratch {
    std::vector<geometry::TriangleSetup> records;  // one chunk's, in submission order
    raster::Binner::Scratch bins;
    raster::FrameBuffer tile;       // 64×64: the tile being drawn, in frames of one batch
    raster::FrameBuffer translucent;  // 64×64: raster::TileWork::translucentDepth's scratch
    std::vector<uint32_t> visible;  // 64×64 deferred-shading records (TileWork::visible)
    std::unique_ptr<raster::Occupancy> occupancy;  // the tile's, in frames of one batch
    std::vector<uint32_t> objects;  // with masking: the chunk's records' objects (TileWork)
    std::vector<raster::AttributeSetup> attributes;  // pixel shading: the records', in their order
    // The tile's lists, one per chunk: entries, sizes, objects and boxes (TileWork).
    std::vector<const uint32_t*> lists;
    std::vector<uint32_t> listSizes;
    std::vector<const uint32_t*> listObjects;
    std::vector<const raster::Binner::Box*> listBoxes;
  };
  std::vector<geometry::ObjectBound> objects_;     // with masking: every draw call's bound
  std::vector<raster::Occupancy> frameOccupancy_;  // every tile's, in frames of several batches
  std::vector<geometry::TriangleSetup> setups_;    // the batch's, grouped by tile within each chunk
  std::vector<raster::AttributeSetup>
      attributes_;                      // ShadeMode::material: setups_[i]'s is attributes_[i]
  std::vector<WorkerScratch> scratch_;  // one per pool worker
  std::vector<raster::RasterStats> tileStats_;
  std::vector<SetupCounts> chunkCounts_;  // the batch's, per chunk
  std::vector<uint8_t> opaqueDone_;       // per tile: the afterOpaque passes have run
  std::vector<int> drawnTiles_;           // the tiles this part draws (every tile unshared)
  // Frames with light points and one batch (Frame::wavefront): each tile's colour (and depth, for a
  // sink that reads it) drawn in a buffer of its own, kept until its lights are drawn — only the
  // wavefront's tiles at once, about a line of them.
  std::vector<std::unique_ptr<raster::FrameBuffer>> tileBuffers_;  // every one made, kept
  std::vector<std::vector<raster::FrameBuffer*>> freeTileBuffers_;  // per worker
  std::mutex tileBuffersMutex_;
  std::vector<raster::FrameBuffer*> tileBufferOf_;  // per tile: the one it is drawn in
  // Per tile: how many tiles of its 3×3 neighbourhood are still to be drawn and seen (before its
  // lights are drawn).
  std::unique_ptr<std::atomic<int>[]> unlit_;
  size_t waitTiles_ = 0;  // their size
  // FrameSettings::passes by stage: those that run once a tile's opaque triangles are in, and
  // those after its last triangle.
  std::vector<raster::TilePass*> afterOpaque_, afterTranslucent_;
};

}  // namespace sv::render
