#include "render/frame_renderer.h"

#include <algorithm>
#include <cmath>

#include "core/streaming.h"
#include "core/timing.h"

namespace sv::render {
namespace {

// Triangles are processed in batches (bounded memory for the setup records: FrameSettings::
// batchTriangles × 160 bytes), each batch set up in chunks. Neither size depends on the thread
// count, so the draw order inside every tile — and so the image — never does.
// Every batch walks the frame buffer once (20 MB at 1920×1080, far beyond L2), so batches are
// large: small batches left 10-px triangles waiting for frame-buffer blocks to come back from L3.
// Chunks are as large as leaves a batch at least four (setup runs a chunk per thread at a time),
// from 2^11 to 2^14 triangles: larger chunks give a tile longer runs of contiguous records
// (docs/performance.md, "Setup and binning").
constexpr uint32_t kMinChunkTriangles = 1u << 11, kMaxChunkTriangles = 1u << 14;
uint32_t chunkTriangles(uint32_t batch) {
  uint32_t chunk = kMaxChunkTriangles;
  while (chunk > kMinChunkTriangles && batch < 4 * chunk) chunk /= 2;
  return chunk;
}

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

// Object-space culling before setup (SPEC §4, seed 004): whether the object bounded by `bound`
// lies in occupied windows of every tile it reaches — the occupancy earlier batches left — of
// those this part draws (`share`).
bool hiddenInFrame(const geometry::ObjectBound& bound, const std::vector<raster::Occupancy>& tiles,
                   int tilesX, raster::Masking masking, const TileShare& share) {
  if (bound.minX > bound.maxX || bound.minY > bound.maxY) return false;  // off screen: setup culls
  for (int ty = bound.minY >> raster::kTileLog2; ty <= bound.maxY >> raster::kTileLog2; ++ty)
    for (int tx = bound.minX >> raster::kTileLog2; tx <= bound.maxX >> raster::kTileLog2; ++tx)
      if (share.owns(tx, ty) && !raster::objectHidden(tiles[size_t(ty * tilesX + tx)], bound, tx, ty, masking))
        return false;
  return true;
}

}  // namespace

struct FrameRenderer::Frame {
  const raster::CoverageTables* coverage;  // anti-aliasing, or nullptr
  int samples;
  geometry::Viewport viewport;
  uint32_t triangles, batchTriangles, chunkSize;
  // One batch: each tile is cleared, drawn and handed on in a per-thread 64×64 buffer. Several:
  // the tiles persist in a whole-frame buffer from batch to batch.
  bool wholeFrame;
  bool lights;  // some pass is of stage lights: they run last, before the sink
  // Lights in an unshared frame of one batch: each tile drawn in a buffer of its own, seen, and lit
  // as soon as the tiles around it are seen (FrameRenderer::tileDrawn).
  bool wavefront;
  int tilesX, tilesY, tiles;
  // Colour sums (raster::TileWork::sums): each sample written at most once and read by nothing but
  // the resolve — priority masking (every written sample occupied), opaque triangles only (a
  // cut-out occupies nothing, a blended one reads what is behind), no pass besides the polygons.
  bool sums;
  // Priority masking tests each list entry's box before reading its records (TileWork::listBoxes),
  // unless some triangle is translucent (never dropped by occupancy).
  bool boxes;
  bool masking, pixelShading;
  // Some triangle is translucent and some pass runs after the opaque ones: such a pass may want
  // the translucent surfaces' depth (raster::TileTarget::translucentDepth), drawn in scratch.
  bool translucentDepth;
  // How much of each pixel-shading record binning stores: the second line only when some material
  // of the frame reads it (AttributeSetup) — the layout's attributes are all the frame's
  // materials read.
  size_t recordBytes;
  uint16_t clear16[3];
};

FrameRenderer::Frame FrameRenderer::frameOf(const DrawPackets& packets,
                                            const FrameSettings& settings) const {
  Frame f;
  f.coverage = settings.samples > 1 ? raster::CoverageTables::forCount(settings.samples) : nullptr;
  f.samples = f.coverage ? f.coverage->samples : 1;
  f.viewport = geometry::Viewport{settings.width, settings.height, f.coverage != nullptr};
  f.triangles = static_cast<uint32_t>(packets.indices.size() / 3);
  f.batchTriangles = std::clamp<uint32_t>(settings.batchTriangles, 1, kMaxBatchTriangles);
  f.chunkSize = chunkTriangles(std::min(f.triangles, f.batchTriangles));
  // Light points read the depth of the tiles around their own (TilePass::seeTile). A frame of
  // several batches keeps the whole frame anyway, and a shared frame's lights read what the other
  // parts drew (TilePass::exchange), once all are drawn: their lights run after every tile. Else
  // they follow the tiles as a wavefront, and only its tiles are kept.
  f.lights = std::any_of(settings.passes.begin(), settings.passes.end(), [](auto* p) {
    return p->stage() == raster::PassStage::lights;
  });
  f.wholeFrame = f.triangles > f.batchTriangles || (f.lights && settings.share.shared());
  f.wavefront = f.lights && !f.wholeFrame;
  f.tilesX = (settings.width + raster::kTileSize - 1) >> raster::kTileLog2;
  f.tilesY = (settings.height + raster::kTileSize - 1) >> raster::kTileLog2;
  f.tiles = f.tilesX * f.tilesY;
  f.sums = settings.colorSums && settings.masking == raster::Masking::priority && f.samples > 1 &&
           settings.passes.empty() && !settings.debugOccupancy &&
           (settings.shade == raster::ShadeMode::material ||
            settings.shade == raster::ShadeMode::gouraud);
  bool blended = false;  // some triangle is translucent
  for (const DrawCall& call : packets.calls) {
    if (call.material && call.material->alpha != shade::AlphaUse::opaque) f.sums = false;
    blended |= call.material && call.material->alpha == shade::AlphaUse::blend;
  }
  f.boxes = settings.masking == raster::Masking::priority && !blended;
  f.masking = settings.masking != raster::Masking::none;
  f.pixelShading = settings.shade == raster::ShadeMode::material;
  f.translucentDepth = f.pixelShading && blended &&
                       std::any_of(settings.passes.begin(), settings.passes.end(), [](auto* p) {
                         return p->stage() != raster::PassStage::lights;
                       });
  f.recordBytes = raster::AttributeSetup::readsSecondLine(packets.attributeLayout.stored)
                      ? sizeof(raster::AttributeSetup)
                      : raster::AttributeSetup::kLineBytes;
  for (int ch = 0; ch < 3; ++ch)
    f.clear16[ch] = static_cast<uint16_t>(
        std::lround(std::clamp(settings.clearColor[ch], 0.0f, 1.0f) * 65535.0f));
  if (settings.shade == raster::ShadeMode::overdraw || settings.shade == raster::ShadeMode::levels)
    std::fill_n(f.clear16, 3, uint16_t(0));
  return f;
}

// The frame's buffers, kept from frame to frame: setup records, per-worker scratch, occupancy,
// object bounds, per-tile statistics.
void FrameRenderer::prepareBuffers(const DrawPackets& packets, const Frame& f) {
  const uint32_t firstBatch = std::min(f.triangles, f.batchTriangles);
  if (f.wholeFrame) fb_.resize(f.viewport.width, f.viewport.height, f.samples, f.sums);
  setups_.resize(std::max<size_t>(setups_.size(), firstBatch));
  if (f.pixelShading) attributes_.resize(std::max<size_t>(attributes_.size(), firstBatch));
  const int maxChunks = std::max(1, int((firstBatch + f.chunkSize - 1) / f.chunkSize));
  scratch_.resize(size_t(pool_.threadCount()));
  for (WorkerScratch& w : scratch_) {
    w.records.resize(f.chunkSize);
    if (!f.wholeFrame) w.tile.resize(raster::kTileSize, raster::kTileSize, f.samples, f.sums);
    if (f.translucentDepth) w.translucent.resize(raster::kTileSize, raster::kTileSize, f.samples);
    if (f.pixelShading && f.samples == 1) w.visible.assign(raster::kTilePixels, ~0u);
    if (f.masking && !f.wholeFrame && !w.occupancy)
      w.occupancy = std::make_unique<raster::Occupancy>();
    if (f.masking) w.objects.resize(f.chunkSize);
    if (f.pixelShading) w.attributes.resize(f.chunkSize);
    w.lists.resize(size_t(maxChunks));
    w.listSizes.resize(size_t(maxChunks));
    w.listObjects.resize(size_t(maxChunks));
    w.listBoxes.resize(size_t(maxChunks));
  }
  if (f.masking && f.wholeFrame) frameOccupancy_.resize(size_t(f.tiles));
  // Object-space culling: every draw call's bound; its records carry the call's index, or
  // kNoObject when it has no bound or is translucent (blended after all opaque ones, so occupied
  // windows do not hide it).
  objects_.clear();
  if (f.masking)
    for (const DrawCall& call : packets.calls) objects_.push_back(call.bound);
  if (f.wavefront) {
    if (waitTiles_ != size_t(f.tiles)) {
      unlit_ = std::make_unique<std::atomic<int>[]>(size_t(f.tiles));
      waitTiles_ = size_t(f.tiles);
    }
    for (int t = 0; t < f.tiles; ++t) {
      const int x = t % f.tilesX, y = t / f.tilesX;
      const int around = (std::min(f.tilesX - 1, x + 1) - std::max(0, x - 1) + 1) *
                         (std::min(f.tilesY - 1, y + 1) - std::max(0, y - 1) + 1);
      unlit_[size_t(t)].store(around, std::memory_order_relaxed);
    }
    tileBufferOf_.assign(size_t(f.tiles), nullptr);
    freeTileBuffers_.resize(size_t(pool_.threadCount()));  // a free list per worker
  }
  tileStats_.assign(size_t(f.tiles), raster::RasterStats{});
  opaqueDone_.assign(size_t(f.tiles), 0);
  chunkCounts_.resize(size_t(maxChunks));
}

// Each pass prepared for the frame, and sorted by stage (stably: a stage's passes keep the order
// render gave them).
void FrameRenderer::preparePasses(const FrameSettings& settings, const Frame& f) {
  afterOpaque_.clear();
  afterTranslucent_.clear();
  const raster::PassFrame frame{
      settings.width, settings.height, f.samples,
      f.coverage,     &pool_,          f.lights && settings.share.shared() ? &fb_ : nullptr,
      settings.share};
  for (raster::PassStage stage :
       {raster::PassStage::surfaces, raster::PassStage::volumes, raster::PassStage::lights})
    for (raster::TilePass* pass : settings.passes) {
      if (pass->stage() != stage) continue;
      pass->prepare(frame);
      (stage == raster::PassStage::lights ? afterTranslucent_ : afterOpaque_).push_back(pass);
    }
}

Status FrameRenderer::render(const DrawPackets& packets, const FrameSettings& settings,
                             FrameStats& stats) {
  const Frame f = frameOf(packets, settings);
  prepareBuffers(packets, f);
  drawnTiles_.clear();
  for (int tile = 0; tile < f.tiles; ++tile)
    if (settings.share.owns(tile % f.tilesX, tile / f.tilesX)) drawnTiles_.push_back(tile);
  // The wavefront keeps the tiles drawn and not yet lit — those within a line of tiles of the
  // front: drawn along the shorter side, the lines are shorter (18 tiles kept at 1920×1080, not 31).
  // (Bands of 2, 4 or 8 tiles across, most tiles lit a few after they are drawn, measured the
  // same at 16 samples.)
  if (f.wavefront && f.tilesY < f.tilesX)
    for (int i = 0; i < f.tiles; ++i)
      drawnTiles_[size_t(i)] = (i % f.tilesY) * f.tilesX + i / f.tilesY;
  preparePasses(settings, f);
  stats.trianglesIn += f.triangles;
  addTraversalCounts(packets.traversal, stats);
  // Always run at least one (empty) batch, so the tiles get cleared.
  for (uint32_t begin = 0; begin == 0 || begin < f.triangles; begin += f.batchTriangles) {
    Batch batch;
    batch.begin = begin;
    batch.end = std::min(f.triangles, begin + f.batchTriangles);
    batch.chunks = int((batch.end - begin + f.chunkSize - 1) / f.chunkSize);
    batch.first = begin == 0;
    batch.last = batch.end == f.triangles;
    auto t0 = core::Clock::now();
    setUpBatch(packets, settings, f, batch, stats);
    stats.setupMs += core::msSince(t0);
    t0 = core::Clock::now();
    drawTiles(settings, f, batch);
    stats.rasterMs += core::msSince(t0);
  }
  if (f.lights && f.wholeFrame) {
    // A shared frame's lights read depth the other parts drew (TilePass::exchange).
    if (settings.share.shared())
      for (raster::TilePass* pass : afterTranslucent_)
        if (Status s = pass->exchange(); !s) return s;
    const auto t0 = core::Clock::now();
    pool_.parallelFor(drawnTiles_.size(), [&](size_t i, int worker) {
      const int tile = drawnTiles_[i];
      const raster::TileTarget target{tile % f.tilesX, tile / f.tilesX, fb_.tileDepth(tile),
                                      fb_.tileColor(tile), worker};
      for (raster::TilePass* pass : afterTranslucent_) pass->seeTile(target);
    });
    pool_.parallelFor(drawnTiles_.size(), [&](size_t i, int worker) {
      const int tile = drawnTiles_[i];
      finishTile(settings, tile, fb_.tileDepth(tile), fb_.tileColor(tile), nullptr, worker);
    });
    stats.rasterMs += core::msSince(t0);
  }
  addTileStats(stats);
  for (const raster::TilePass* pass : settings.passes) pass->addStats(stats);
  return {};
}

void FrameRenderer::setUpBatch(const DrawPackets& packets, const FrameSettings& settings,
                               const Frame& f, const Batch& batch, FrameStats& stats) {
  binner_.reset(std::max(batch.chunks, 1), f.tilesX, f.tilesY);
  pool_.parallelFor(size_t(batch.chunks), [&](size_t chunk, int worker) {
    chunkCounts_[chunk] = setUpChunk(packets, settings, f, batch, int(chunk), worker);
  });
  for (int i = 0; i < batch.chunks; ++i) {
    const SetupCounts& c = chunkCounts_[size_t(i)];
    stats.drawn += c.drawn;
    stats.culledFacing += c.facing;
    stats.culledOutside += c.outside;
    stats.culledDegenerate += c.degenerate;
    stats.culledInvalid += c.invalid;
    stats.culledOccluded += c.occluded;
  }
}

// One chunk: runs of triangles that share a draw call (a culling mode, a material), set up several
// at a time, then binned.
FrameRenderer::SetupCounts FrameRenderer::setUpChunk(const DrawPackets& packets,
                                                     const FrameSettings& settings, const Frame& f,
                                                     const Batch& batch, int chunk, int worker) {
  WorkerScratch& scratch = scratch_[size_t(worker)];
  const uint32_t begin = batch.begin + uint32_t(chunk) * f.chunkSize;
  const uint32_t end = std::min(batch.end, begin + f.chunkSize);
  uint64_t outcomes[geometry::kSetupOutcomes] = {};
  uint32_t n = 0;
  SetupCounts c;
  CallCursor cursor{packets.calls};
  for (uint32_t tri = begin; tri < end;) {
    const DrawCall* call = cursor.find(tri);
    const uint32_t runEnd =
        call ? std::min(end, call->firstTriangle + call->triangleCount) : tri + 1;
    const bool blend = call && call->material && call->material->alpha == shade::AlphaUse::blend;
    const uint32_t object = f.masking && call && call->bounded && !blend
                                ? uint32_t(call - packets.calls.data())
                                : raster::kNoObject;
    if (object != raster::kNoObject && f.wholeFrame && !batch.first &&
        hiddenInFrame(objects_[object], frameOccupancy_, f.tilesX, settings.masking,
                      settings.share)) {
      c.occluded += runEnd - tri;
      tri = runEnd;
      continue;
    }
    const uint32_t first = n;
    // Pixel shading's planes for the drawn triangles of a call with a material, set up with
    // them (stored after binning, as the records are).
    const shade::MaterialShading* material = call ? call->material : nullptr;
    geometry::AttributeRequest request;
    if (f.pixelShading && material) {
      request.values = packets.attributes.data();
      request.valueStride = size_t(packets.attributeLayout.stride);
      request.slots = packets.attributeLayout.slot;
      request.count = shade::kAttributeCount;
      request.used = shade::attributesUsed(*material, *settings.environment);
      request.out = scratch.attributes[n].planes;
      request.outStride = sizeof(raster::AttributeSetup);
    }
    n += uint32_t(geometry::setupTriangles(
        packets.vertices.data(), &packets.indices[size_t(tri) * 3], runEnd - tri, f.viewport,
        call ? call->cull : geometry::CullMode::none, scratch.records.data() + n, outcomes, tri,
        request.out ? &request : nullptr));
    if (f.masking) std::fill(scratch.objects.begin() + first, scratch.objects.begin() + n, object);
    if (f.pixelShading)
      for (uint32_t r = first; r < n; ++r) scratch.attributes[r].material = material;
    tri = runEnd;
  }
  c.drawn = outcomes[int(geometry::SetupOutcome::drawn)];
  c.facing = outcomes[int(geometry::SetupOutcome::culledFacing)];
  c.outside = outcomes[int(geometry::SetupOutcome::culledOutside)];
  c.degenerate = outcomes[int(geometry::SetupOutcome::culledDegenerate)];
  c.invalid = outcomes[int(geometry::SetupOutcome::culledInvalid)];
  const uint32_t storageBase = begin - batch.begin;
  binner_.binChunk(chunk, scratch.records.data(), n, setups_.data() + storageBase, storageBase,
                   scratch.bins, f.masking ? scratch.objects.data() : nullptr, f.boxes);
  // Pixel shading's planes, stored as the setup records are (grouped by tile): a tile finds each
  // triangle's from its list entry and reads them in runs, as it reads the records. Only their
  // first line when no material of the frame reads the second (a textured, unlit frame's): half
  // the bytes streamed.
  if (f.pixelShading)
    core::gatherStreaming(attributes_.data() + storageBase, scratch.attributes.data(),
                          scratch.bins.order.data(), n, f.recordBytes);
  return c;
}

void FrameRenderer::drawTiles(const FrameSettings& settings, const Frame& f, const Batch& batch) {
  pool_.parallelFor(drawnTiles_.size(), [&](size_t i, int worker) {
    drawTile(settings, f, batch, drawnTiles_[i], worker);
  });
}

// One tile's lists, in chunk order; after the frame's last batch its lights passes and its sink
// (with light points, once every tile is drawn: FrameRenderer::render).
void FrameRenderer::drawTile(const FrameSettings& settings, const Frame& f, const Batch& batch,
                             int tile, int worker) {
  WorkerScratch& scratch = scratch_[size_t(worker)];
  const int lists = binner_.chunkCount();
  for (int c = 0; c < lists; ++c) {
    const raster::Binner::List l = binner_.list(c, tile);
    scratch.lists[size_t(c)] = l.data;
    scratch.listSizes[size_t(c)] = l.size;
    scratch.listObjects[size_t(c)] = l.objects;
    scratch.listBoxes[size_t(c)] = l.boxes;
  }
  raster::TileWork w;
  w.tileX = tile % f.tilesX;
  w.tileY = tile / f.tilesX;
  raster::FrameBuffer* kept =
      f.wavefront ? (tileBufferOf_[size_t(tile)] = takeTileBuffer(f.samples, worker)) : nullptr;
  raster::FrameBuffer& buffer = f.wholeFrame ? fb_ : kept ? *kept : scratch.tile;
  const int index = f.wholeFrame ? tile : 0;
  w.depth = (kept && !settings.depthToSink ? scratch.tile : buffer).tileDepth(index);
  w.color = buffer.tileColor(index);
  if (f.sums) w.sums = buffer.tileSums(index);
  w.clear = batch.first;
  std::copy_n(f.clear16, 3, w.clearColor);
  w.setups = setups_.data();
  w.lists = scratch.lists.data();
  w.listSizes = scratch.listSizes.data();
  w.listCount = lists;
  w.shade = settings.shade;
  w.coverage = f.coverage;
  if (f.pixelShading) {
    w.attributes = attributes_.data();
    w.environment = settings.environment;
    if (f.samples == 1) w.visible = scratch.visible.data();
  }
  w.masking = settings.masking;
  w.debugOccupancy = settings.debugOccupancy && batch.last;
  if (f.masking) {
    w.occupancy = f.wholeFrame ? &frameOccupancy_[size_t(tile)] : scratch.occupancy.get();
    w.listObjects = scratch.listObjects.data();
    if (f.boxes) w.listBoxes = scratch.listBoxes.data();
    w.objects = objects_.data();
  }
  w.lastBatch = batch.last;
  w.afterOpaque = afterOpaque_;
  if (f.translucentDepth) {
    w.translucentDepth = scratch.translucent.tileDepth(0);
    w.translucentColor = scratch.translucent.tileColor(0);
  }
  w.worker = worker;
  w.opaqueDone = &opaqueDone_[size_t(tile)];
  raster::rasterizeTile(w, tileStats_[size_t(tile)]);
  if (!batch.last) return;
  if (f.wavefront) {
    const raster::TileTarget target{w.tileX, w.tileY, w.depth, w.color, worker};
    for (raster::TilePass* pass : afterTranslucent_) pass->seeTile(target);
    tileDrawn(settings, f, tile, worker);
  } else if (!f.lights) {
    finishTile(settings, tile, w.depth, w.color, w.sums, worker);
  }
}

// The wavefront (docs/lights.md): a tile is seen as soon as it is drawn, and lit once the 3×3
// tiles around it are seen — so the tiles kept are those drawn and not yet lit, about a line of
// them. Whichever thread completes a tile's neighbourhood lights it; the count's acq_rel orders
// the drawn colour, and what the passes kept in seeTile, before what reads them. What a tile gets
// never depends on which thread that is.
void FrameRenderer::tileDrawn(const FrameSettings& settings, const Frame& f, int tile, int worker) {
  const int tx = tile % f.tilesX, ty = tile / f.tilesX;
  for (int y = std::max(0, ty - 1); y <= std::min(f.tilesY - 1, ty + 1); ++y)
    for (int x = std::max(0, tx - 1); x <= std::min(f.tilesX - 1, tx + 1); ++x) {
      const int lit = y * f.tilesX + x;
      if (unlit_[size_t(lit)].fetch_sub(1, std::memory_order_acq_rel) != 1) continue;
      raster::FrameBuffer* buffer = tileBufferOf_[size_t(lit)];
      finishTile(settings, lit, settings.depthToSink ? buffer->tileDepth(0) : nullptr,
                 buffer->tileColor(0), nullptr, worker);
      giveTileBuffer(buffer, worker);
    }
}

raster::FrameBuffer* FrameRenderer::takeTileBuffer(int samples, int worker) {
  raster::FrameBuffer* buffer = nullptr;
  {
    std::lock_guard lock(tileBuffersMutex_);
    for (int k = 0; k < pool_.threadCount() && !buffer; ++k) {
      std::vector<raster::FrameBuffer*>& free =
          freeTileBuffers_[size_t((worker + k) % pool_.threadCount())];
      if (free.empty()) continue;
      buffer = free.back();
      free.pop_back();
    }
    if (!buffer) buffer = tileBuffers_.emplace_back(std::make_unique<raster::FrameBuffer>()).get();
  }
  buffer->resize(raster::kTileSize, raster::kTileSize, samples);  // allocates only when it grows
  return buffer;
}

void FrameRenderer::giveTileBuffer(raster::FrameBuffer* buffer, int worker) {
  std::lock_guard lock(tileBuffersMutex_);
  freeTileBuffers_[size_t(worker)].push_back(buffer);
}

// A drawn tile's last passes (stage lights) and its sink.
void FrameRenderer::finishTile(const FrameSettings& settings, int tile, float* depth,
                               uint16_t* color, int32_t* sums, int worker) {
  const int tilesX = (settings.width + raster::kTileSize - 1) >> raster::kTileLog2;
  const raster::TileTarget target{tile % tilesX, tile / tilesX, depth, color, worker};
  for (raster::TilePass* pass : afterTranslucent_) pass->drawTile(target);
  if (settings.finishTile) settings.finishTile(tile, depth, color, sums);
}

void FrameRenderer::addTileStats(FrameStats& stats) const {
  raster::RasterStats total;
  for (const auto& s : tileStats_) total.add(s);
  for (int i = 0; i < raster::kStatLevels; ++i) stats.windows[i] += total.windows[i];
  stats.fullWindows += total.fullWindows;
  stats.occludedWindows += total.occludedWindows;
  stats.occludedTriangles += total.occludedTriangles;
  stats.occludedObjects += total.occludedObjects;
  stats.partialBlocks += total.partialBlocks;
  stats.fragments += total.fragments;
  stats.hiddenFragments += total.hiddenFragments;
  stats.hybridWoken += total.hybridWoken;
  stats.shadedByList += total.shadedByList;
  stats.shadedByScan += total.shadedByScan;
}

}  // namespace sv::render
