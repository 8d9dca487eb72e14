#include "raster/binner.h"

#include "core/streaming.h"
#include "raster/framebuffer.h"

namespace sv::raster {

void Binner::reset(int chunks, int tilesX, int tilesY) {
  if (chunkLists_.size() < size_t(chunks)) chunkLists_.resize(size_t(chunks));
  for (int c = 0; c < chunks; ++c) chunkLists_[size_t(c)].offsets.clear();
  chunks_ = chunks;
  tilesX_ = tilesX;
  tiles_ = tilesX * tilesY;
}

void Binner::binChunk(int chunk, const geometry::TriangleSetup* records, uint32_t n,
                      geometry::TriangleSetup* storage, uint32_t storageBase, Scratch& scratch,
                      const uint32_t* objects, bool boxes) {
  // Counting sort by the tile of the top-left corner; stable, so each group keeps submission order.
  scratch.key.resize(n);
  scratch.position.resize(n);
  scratch.count.assign(size_t(tiles_) + 1, 0);
  for (uint32_t i = 0; i < n; ++i) {
    const geometry::TriangleSetup& t = records[i];
    const uint32_t key = uint32_t((t.minY >> kTileLog2) * tilesX_ + (t.minX >> kTileLog2));
    scratch.key[i] = key;
    ++scratch.count[key + 1];
  }
  for (int k = 0; k < tiles_; ++k) scratch.count[k + 1] += scratch.count[k];
  scratch.order.resize(n);
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t p = scratch.count[scratch.key[i]]++;
    scratch.position[i] = p;
    scratch.order[p] = i;
  }
  // Copied in storage order: sequential writes to memory that is not in cache (the storage is the
  // size of a batch) and scattered reads from the chunk's records, which are in L2 — not in record
  // order with scattered writes (docs/performance.md, "Setup and binning"). Streaming stores: the
  // tiles read the records only after all chunks are binned (core/streaming.h).
  core::gatherStreaming(storage, records, scratch.order.data(), n);
  // The lists: count the entries per tile, then place them in submission order.
  ChunkLists& out = chunkLists_[size_t(chunk)];
  out.offsets.assign(size_t(tiles_) + 1, 0);
  auto forEachTile = [&](const geometry::TriangleSetup& t, auto fn) {
    const int tx0 = t.minX >> kTileLog2, tx1 = t.maxX >> kTileLog2;
    const int ty0 = t.minY >> kTileLog2, ty1 = t.maxY >> kTileLog2;
    for (int ty = ty0; ty <= ty1; ++ty)
      for (int tx = tx0; tx <= tx1; ++tx) fn(ty * tilesX_ + tx);
  };
  for (uint32_t i = 0; i < n; ++i)
    forEachTile(records[i], [&](int tile) { ++out.offsets[tile + 1]; });
  for (int k = 0; k < tiles_; ++k) out.offsets[k + 1] += out.offsets[k];
  out.entries.resize(out.offsets[size_t(tiles_)]);
  // The optional parallel arrays are placed in the same pass, at the entries' positions.
  out.objects.resize(objects ? out.entries.size() : 0);
  out.boxes.resize(boxes ? out.entries.size() : 0);
  scratch.cursor.assign(out.offsets.begin(), out.offsets.end() - 1);
  for (uint32_t i = 0; i < n; ++i) {
    const geometry::TriangleSetup& t = records[i];
    const uint32_t index = storageBase + scratch.position[i];
    const Box box{t.minX, t.minY, t.maxX, t.maxY};
    forEachTile(t, [&](int tile) {
      const uint32_t at = scratch.cursor[tile]++;
      out.entries[at] = index;
      if (objects) out.objects[at] = objects[i];
      if (boxes) out.boxes[at] = box;
    });
  }
}

}  // namespace sv::raster
