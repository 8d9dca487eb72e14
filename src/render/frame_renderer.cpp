#include "render/frame_renderer.h"

#include <algorithm>
#include <chrono>

#include "core/streaming.h"

namespace sv::render {
namespace {

// Triangles are processed in batches (bounded memory for the setup records: FrameSettings::
// batchTriangles × 160 bytes), each batch set up in chunks. Neither size depends on the thread
// count, so the draw order inside every tile — and so the image — never does.
// Every batch walks the frame buffer once (20 MB at 1920×1080, far beyond L2), so batches are
// large: with 2^14-triangle batches, 100k triangles of 10 px spent over half their tile time
// waiting for frame-buffer blocks to come back from L3 (perf: the depth load in shadeBlock).
// Chunks are as large as leaves a batch at least four (setup runs a chunk per thread at a time),
// from 2^11 to 2^14 triangles: larger chunks give a tile longer runs of contiguous records (with
// chunks of 2^14 instead of 2^13, tris 100k × 10 px ×0.948, textured ×0.982).
constexpr uint32_t kMinChunkTriangles = 1u << 11, kMaxChunkTriangles = 1u << 14;
uint32_t chunkTriangles(uint32_t batch) {
  uint32_t chunk = kMaxChunkTriangles;
  while (chunk > kMinChunkTriangles && batch < 4 * chunk) chunk /= 2;
  return chunk;
}

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

struct SetupCounts {
  uint64_t facing = 0, outside = 0, degenerate = 0, invalid = 0, occluded = 0, drawn = 0;
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

// Object-space culling before setup (SPEC §4, seed 004): whether the object bounded by `bound`
// lies in occupied windows of every tile it reaches — the occupancy earlier batches left.
bool hiddenInFrame(const geometry::ObjectBound& bound, const std::vector<raster::Occupancy>& tiles,
                   int tilesX, raster::Masking masking) {
  if (bound.minX > bound.maxX || bound.minY > bound.maxY) return false;  // off screen: setup culls
  for (int ty = bound.minY >> raster::kTileLog2; ty <= bound.maxY >> raster::kTileLog2; ++ty)
    for (int tx = bound.minX >> raster::kTileLog2; tx <= bound.maxX >> raster::kTileLog2; ++tx)
      if (!raster::objectHidden(tiles[size_t(ty * tilesX + tx)], bound, tx, ty, masking))
        return false;
  return true;
}

}  // namespace

void FrameRenderer::render(const DrawPackets& packets, const FrameSettings& settings,
                           FrameStats& stats) {
  const raster::CoverageTables* coverage =
      settings.samples > 1 ? raster::CoverageTables::forCount(settings.samples) : nullptr;
  const int samples = coverage ? coverage->samples : 1;
  const geometry::Viewport viewport{settings.width, settings.height, coverage != nullptr};
  const uint32_t triangleCount = static_cast<uint32_t>(packets.indices.size() / 3);
  const uint32_t batchTriangles =
      std::clamp<uint32_t>(settings.batchTriangles, 1, kMaxBatchTriangles);
  // One batch: each tile is cleared, drawn and handed on in a per-thread 64×64 buffer. Several: the
  // tiles persist in a whole-frame buffer from batch to batch.
  const bool wholeFrame = triangleCount > batchTriangles;
  const int tilesX = (settings.width + raster::kTileSize - 1) >> raster::kTileLog2;
  const int tilesY = (settings.height + raster::kTileSize - 1) >> raster::kTileLog2;
  const int tiles = tilesX * tilesY;
  // Colour sums (raster::TileWork::sums): each sample written at most once and read by nothing but
  // the resolve — priority masking (every written sample occupied), opaque triangles only (a
  // cut-out occupies nothing, a blended one reads what is behind).
  bool sums = settings.colorSums && settings.masking == raster::Masking::priority && samples > 1 &&
              !settings.afterOpaque && !settings.debugOccupancy &&
              (settings.shade == raster::ShadeMode::material ||
               settings.shade == raster::ShadeMode::gouraud);
  // Priority masking tests each list entry's box before reading its records (TileWork::listBoxes),
  // unless some triangle is translucent (never dropped by occupancy).
  bool boxes = settings.masking == raster::Masking::priority;
  for (const DrawCall& call : packets.calls) {
    if (call.material && call.material->alpha != shade::AlphaUse::opaque) sums = false;
    if (call.material && call.material->alpha == shade::AlphaUse::blend) boxes = false;
  }
  if (wholeFrame) fb_.resize(settings.width, settings.height, samples, sums);
  uint16_t clear16[3];
  for (int ch = 0; ch < 3; ++ch)
    clear16[ch] = static_cast<uint16_t>(
        std::lround(std::clamp(settings.clearColor[ch], 0.0f, 1.0f) * 65535.0f));
  if (settings.shade == raster::ShadeMode::overdraw || settings.shade == raster::ShadeMode::levels)
    std::fill_n(clear16, 3, uint16_t(0));

  const uint32_t firstBatch = std::min(triangleCount, batchTriangles);
  const uint32_t chunkSize = chunkTriangles(firstBatch);
  setups_.resize(std::max<size_t>(setups_.size(), firstBatch));
  const bool pixelShading = settings.shade == raster::ShadeMode::material;
  if (pixelShading) attributes_.resize(std::max<size_t>(attributes_.size(), firstBatch));
  // How much of each pixel-shading record binning stores: the second line only when some material
  // of the frame reads it (AttributeSetup) — the layout's attributes are all the frame's
  // materials read.
  const size_t recordBytes = raster::AttributeSetup::readsSecondLine(packets.attributeLayout.stored)
                                 ? sizeof(raster::AttributeSetup)
                                 : raster::AttributeSetup::kLineBytes;
  scratch_.resize(size_t(pool_.threadCount()));
  const bool masking = settings.masking != raster::Masking::none;
  for (WorkerScratch& w : scratch_) {
    w.records.resize(chunkSize);
    if (!wholeFrame) w.tile.resize(raster::kTileSize, raster::kTileSize, samples, sums);
    if (settings.shade == raster::ShadeMode::material && samples == 1)
      w.visible.assign(raster::kTilePixels, ~0u);
    if (masking && !wholeFrame && !w.occupancy) w.occupancy = std::make_unique<raster::Occupancy>();
    if (masking) w.objects.resize(chunkSize);
    if (pixelShading) w.attributes.resize(chunkSize);
  }
  if (masking && wholeFrame) frameOccupancy_.resize(size_t(tiles));
  // Object-space culling: every draw call's bound; its records carry the call's index, or
  // kNoObject when it has no bound or is translucent (blended after all opaque ones, so occupied
  // windows do not hide it).
  objects_.clear();
  if (masking)
    for (const DrawCall& call : packets.calls) objects_.push_back(call.bound);
  auto objectOf = [&](const DrawCall* call) {
    const bool blend = call && call->material && call->material->alpha == shade::AlphaUse::blend;
    return call && call->bounded && !blend ? uint32_t(call - packets.calls.data())
                                           : raster::kNoObject;
  };
  tileStats_.assign(size_t(tiles), raster::RasterStats{});
  opaqueDone_.assign(size_t(tiles), 0);
  const int maxChunks = std::max(1, int((firstBatch + chunkSize - 1) / chunkSize));
  std::vector<SetupCounts> counts(static_cast<size_t>(maxChunks));
  std::vector<const uint32_t*> listPtrs(size_t(maxChunks) * pool_.threadCount());
  std::vector<uint32_t> listSizes(listPtrs.size());
  std::vector<const uint32_t*> listObjects(listPtrs.size());
  std::vector<const raster::Binner::Box*> listBoxes(listPtrs.size());
  stats.trianglesIn += triangleCount;

  // Always run at least one (empty) batch, so the tiles get cleared.
  for (uint32_t batch = 0; batch == 0 || batch < triangleCount; batch += batchTriangles) {
    const uint32_t batchEnd = std::min(triangleCount, batch + batchTriangles);
    const int chunks = int((batchEnd - batch + chunkSize - 1) / chunkSize);
    const bool lastBatch = batchEnd == triangleCount;

    // Stage 3: setup and binning, chunk by chunk.
    auto t0 = Clock::now();
    binner_.reset(std::max(chunks, 1), tilesX, tilesY);
    pool_.parallelFor(size_t(chunks), [&](size_t chunk, int worker) {
      WorkerScratch& scratch = scratch_[worker];
      const uint32_t begin = batch + uint32_t(chunk) * chunkSize;
      const uint32_t end = std::min(batchEnd, begin + chunkSize);
      // Runs of triangles that share a draw call (a culling mode), set up several at a time.
      uint64_t outcomes[geometry::kSetupOutcomes] = {};
      uint32_t n = 0;
      uint64_t occluded = 0;
      CallCursor cursor{packets.calls};
      for (uint32_t tri = begin; tri < end;) {
        const DrawCall* call = cursor.find(tri);
        const uint32_t runEnd =
            call ? std::min(end, call->firstTriangle + call->triangleCount) : tri + 1;
        const uint32_t object = masking ? objectOf(call) : raster::kNoObject;
        if (object != raster::kNoObject && wholeFrame && batch > 0 &&
            hiddenInFrame(objects_[object], frameOccupancy_, tilesX, settings.masking)) {
          occluded += runEnd - tri;
          tri = runEnd;
          continue;
        }
        const uint32_t first = n;
        // Pixel shading's planes for the drawn triangles of a call with a material, set up with
        // them (stored after binning, as the records are).
        const shade::MaterialShading* material = call ? call->material : nullptr;
        geometry::AttributeRequest request;
        if (pixelShading && material) {
          request.values = packets.attributes.data();
          request.valueStride = size_t(packets.attributeLayout.stride);
          request.slots = packets.attributeLayout.slot;
          request.count = shade::kAttributeCount;
          request.used = shade::attributesUsed(*material, *settings.environment);
          request.out = scratch.attributes[n].planes;
          request.outStride = sizeof(raster::AttributeSetup);
        }
        n += uint32_t(geometry::setupTriangles(
            packets.vertices.data(), &packets.indices[size_t(tri) * 3], runEnd - tri, viewport,
            call ? call->cull : geometry::CullMode::none, scratch.records.data() + n, outcomes, tri,
            request.out ? &request : nullptr));
        if (masking)
          std::fill(scratch.objects.begin() + first, scratch.objects.begin() + n, object);
        if (pixelShading)
          for (uint32_t r = first; r < n; ++r) scratch.attributes[r].material = material;
        tri = runEnd;
      }
      SetupCounts c;
      c.drawn = outcomes[int(geometry::SetupOutcome::drawn)];
      c.facing = outcomes[int(geometry::SetupOutcome::culledFacing)];
      c.outside = outcomes[int(geometry::SetupOutcome::culledOutside)];
      c.degenerate = outcomes[int(geometry::SetupOutcome::culledDegenerate)];
      c.invalid = outcomes[int(geometry::SetupOutcome::culledInvalid)];
      c.occluded = occluded;
      const uint32_t storageBase = begin - batch;
      binner_.binChunk(int(chunk), scratch.records.data(), n, setups_.data() + storageBase,
                       storageBase, scratch.bins, masking ? scratch.objects.data() : nullptr,
                       boxes);
      // Pixel shading's planes, stored as the setup records are (grouped by tile): a tile finds
      // each triangle's from its list entry and reads them in runs, as it reads the records. Only
      // their first line when no material of the frame reads the second (a textured, unlit
      // frame's): half the bytes streamed (tris 100k × 10 px textured ×0.955).
      if (pixelShading)
        core::gatherStreaming(attributes_.data() + storageBase, scratch.attributes.data(),
                              scratch.bins.order.data(), n, recordBytes);
      counts[chunk] = c;
    });
    for (int i = 0; i < chunks; ++i) {
      stats.drawn += counts[i].drawn;
      stats.culledFacing += counts[i].facing;
      stats.culledOutside += counts[i].outside;
      stats.culledDegenerate += counts[i].degenerate;
      stats.culledInvalid += counts[i].invalid;
      stats.culledOccluded += counts[i].occluded;
    }
    stats.setupMs += msSince(t0);

    // Stage 4: the tiles, each drawing its lists in chunk order.
    t0 = Clock::now();
    const int lists = binner_.chunkCount();
    pool_.parallelFor(size_t(tiles), [&](size_t tile, int worker) {
      const uint32_t** listPtr = listPtrs.data() + size_t(worker) * maxChunks;
      uint32_t* listSize = listSizes.data() + size_t(worker) * maxChunks;
      const uint32_t** listObject = listObjects.data() + size_t(worker) * maxChunks;
      const raster::Binner::Box** listBox = listBoxes.data() + size_t(worker) * maxChunks;
      for (int c = 0; c < lists; ++c) {
        const raster::Binner::List l = binner_.list(c, int(tile));
        listPtr[c] = l.data;
        listSize[c] = l.size;
        listObject[c] = l.objects;
        listBox[c] = l.boxes;
      }
      raster::TileWork w;
      w.tileX = int(tile) % tilesX;
      w.tileY = int(tile) / tilesX;
      raster::FrameBuffer& buffer = wholeFrame ? fb_ : scratch_[worker].tile;
      const int index = wholeFrame ? int(tile) : 0;
      w.depth = buffer.tileDepth(index);
      w.color = buffer.tileColor(index);
      if (sums) w.sums = buffer.tileSums(index);
      w.clear = batch == 0;
      std::copy_n(clear16, 3, w.clearColor);
      w.setups = setups_.data();
      w.lists = listPtr;
      w.listSizes = listSize;
      w.listCount = lists;
      w.shade = settings.shade;
      w.coverage = coverage;
      if (pixelShading) {
        w.attributes = attributes_.data();
        w.environment = settings.environment;
        if (samples == 1) w.visible = scratch_[worker].visible.data();
      }
      w.masking = settings.masking;
      w.debugOccupancy = settings.debugOccupancy && lastBatch;
      if (masking) {
        w.occupancy = wholeFrame ? &frameOccupancy_[tile] : scratch_[worker].occupancy.get();
        w.listObjects = listObject;
        if (boxes) w.listBoxes = listBox;
        w.objects = objects_.data();
      }
      w.lastBatch = lastBatch;
      std::function<void()> afterOpaque;
      if (settings.afterOpaque) {
        afterOpaque = [&, tile, worker] {
          settings.afterOpaque(int(tile), worker, w.depth, w.color);
        };
        w.afterOpaque = &afterOpaque;
        w.opaqueDone = &opaqueDone_[tile];
      }
      raster::rasterizeTile(w, tileStats_[tile]);
      if (lastBatch && settings.finishTile)
        settings.finishTile(int(tile), w.depth, w.color, w.sums);
    });
    stats.rasterMs += msSince(t0);
  }

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
