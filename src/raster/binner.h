// Binning of set-up triangles into screen tiles (SPEC §3.4's alternative to sparse rasters:
// contiguous tiles, each owned by one thread at a time).
//
// Triangles are set up in fixed-size chunks, each chunk binning into its own per-tile lists, so
// that setup runs in parallel without locks; a tile then draws chunk 0's list, chunk 1's, … — the
// submission order, whatever the thread count (SPEC §6).
#pragma once

#include <cstdint>
#include <cstddef>
#include <vector>

#include "geometry/setup.h"

namespace sv::raster {

class Binner {
 public:
  // Empties all lists for `chunks` chunks over a tilesX × tilesY grid (keeps their capacity).
  void reset(int chunks, int tilesX, int tilesY);

  // Adds triangle `index` of chunk `chunk` to every tile its bounding box overlaps.
  void bin(int chunk, uint32_t index, const geometry::TriangleSetup& t);

  int chunkCount() const { return chunks_; }
  const std::vector<uint32_t>& list(int chunk, int tile) const {
    return lists_[size_t(chunk) * tiles_ + tile];
  }

 private:
  int chunks_ = 0, tilesX_ = 0, tiles_ = 0;
  std::vector<std::vector<uint32_t>> lists_;
};

}  // namespace sv::raster
