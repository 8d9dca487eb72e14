// Binning of set-up triangles into screen tiles (SPEC §3.4's alternative to sparse rasters:
// contiguous tiles, each owned by one thread at a time).
//
// Triangles are set up in chunks, each chunk binning into its own per-tile lists, so that setup
// runs in parallel without locks; a tile then draws chunk 0's list, chunk 1's, … — the submission
// order, whatever the thread count (SPEC §6).
//
// A chunk's setup records are stored grouped by the tile of their bounding box's top-left corner
// (a stable counting sort), so a tile reads its records as a few contiguous runs rather than one
// scattered record per triangle. Measured on `tris --count 100000 --area 10`, 1 thread: the same
// triangles presorted by tile rendered in 26 ms instead of 38 — the tile pass was waiting on the
// scattered records (docs/performance.md).
#pragma once

#include <cstdint>
#include <cstddef>
#include <vector>

#include "geometry/setup.h"

namespace sv::raster {

class Binner {
 public:
  // Per-worker temporary arrays for binChunk (kept between calls to avoid reallocation).
  struct Scratch {
    std::vector<uint32_t> key, position, count;
  };

  // Empties all lists for `chunks` chunks over a tilesX × tilesY grid (keeps their capacity).
  void reset(int chunks, int tilesX, int tilesY);

  // Stores the `n` records of chunk `chunk` (in submission order in `records`) into
  // storage[0, n), grouped by tile, and appends storageBase + their position to the list of every
  // tile each one's bounding box overlaps, in submission order. Chunks may be binned concurrently.
  void binChunk(int chunk, const geometry::TriangleSetup* records, uint32_t n,
                geometry::TriangleSetup* storage, uint32_t storageBase, Scratch& scratch);

  int chunkCount() const { return chunks_; }
  const std::vector<uint32_t>& list(int chunk, int tile) const {
    return lists_[size_t(chunk) * tiles_ + tile];
  }

 private:
  int chunks_ = 0, tilesX_ = 0, tiles_ = 0;
  std::vector<std::vector<uint32_t>> lists_;
};

}  // namespace sv::raster
