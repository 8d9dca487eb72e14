#include "raster/binner.h"

#include "raster/framebuffer.h"

namespace sv::raster {

void Binner::reset(int chunks, int tilesX, int tilesY) {
  const size_t need = size_t(chunks) * tilesX * tilesY;
  if (lists_.size() < need) lists_.resize(need);
  for (size_t i = 0; i < need; ++i) lists_[i].clear();
  chunks_ = chunks;
  tilesX_ = tilesX;
  tiles_ = tilesX * tilesY;
}

void Binner::binChunk(int chunk, const geometry::TriangleSetup* records, uint32_t n,
                      geometry::TriangleSetup* storage, uint32_t storageBase, Scratch& scratch) {
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
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t p = scratch.count[scratch.key[i]]++;
    scratch.position[i] = p;
    storage[p] = records[i];
  }
  std::vector<uint32_t>* base = lists_.data() + size_t(chunk) * tiles_;
  for (uint32_t i = 0; i < n; ++i) {
    const geometry::TriangleSetup& t = records[i];
    const uint32_t index = storageBase + scratch.position[i];
    const int tx0 = t.minX >> kTileLog2, tx1 = t.maxX >> kTileLog2;
    const int ty0 = t.minY >> kTileLog2, ty1 = t.maxY >> kTileLog2;
    for (int ty = ty0; ty <= ty1; ++ty)
      for (int tx = tx0; tx <= tx1; ++tx) base[ty * tilesX_ + tx].push_back(index);
  }
}

}  // namespace sv::raster
