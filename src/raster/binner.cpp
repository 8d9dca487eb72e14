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

void Binner::bin(int chunk, uint32_t index, const geometry::TriangleSetup& t) {
  const int tx0 = t.minX >> kTileLog2, tx1 = t.maxX >> kTileLog2;
  const int ty0 = t.minY >> kTileLog2, ty1 = t.maxY >> kTileLog2;
  std::vector<uint32_t>* base = lists_.data() + size_t(chunk) * tiles_;
  for (int ty = ty0; ty <= ty1; ++ty)
    for (int tx = tx0; tx <= tx1; ++tx) base[ty * tilesX_ + tx].push_back(index);
}

}  // namespace sv::raster
