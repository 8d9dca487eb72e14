// Binning of set-up triangles into screen tiles (SPEC §3.4's alternative to sparse rasters:
// contiguous tiles, each owned by one thread at a time).
//
// Triangles are set up in chunks, each chunk binning into its own per-tile lists, so that setup
// runs in parallel without locks; a tile then draws chunk 0's list, chunk 1's, … — the submission
// order, whatever the thread count (SPEC §6).
//
// A chunk's setup records are stored grouped by the tile of their bounding box's top-left corner
// (a stable counting sort), so a tile reads its records as a few contiguous runs rather than one
// scattered record per triangle: unsorted, the tile pass waited on the scattered records
// (docs/performance.md, "Setup and binning").
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "geometry/setup.h"

namespace sv::raster {

class Binner {
 public:
  // Per-worker temporary arrays for binChunk (kept between calls to avoid reallocation). After a
  // call, order[p] is the position in `records` of the record stored at storage[p].
  struct Scratch {
    std::vector<uint32_t> key, position, order, count, cursor;
  };

  // Empties all lists for `chunks` chunks over a tilesX × tilesY grid (keeps their capacity).
  void reset(int chunks, int tilesX, int tilesY);

  // Stores the `n` records of chunk `chunk` (in submission order in `records`) into
  // storage[0, n), grouped by tile, and appends storageBase + their position to the list of every
  // tile each one's bounding box overlaps, in submission order. Chunks may be binned concurrently.
  // With `objects` (per record, in the order of `records`), each list entry's object goes to the
  // list's parallel `objects` array; with `boxes`, its record's bounding box to `boxes`.
  void binChunk(int chunk, const geometry::TriangleSetup* records, uint32_t n,
                geometry::TriangleSetup* storage, uint32_t storageBase, Scratch& scratch,
                const uint32_t* objects = nullptr, bool boxes = false);

  // A record's bounding box (TriangleSetup::minX …), beside its list entry: priority masking tests
  // it against the tile's occupancy without reading the record (TileWork::listBoxes).
  struct Box {
    int16_t minX, minY, maxX, maxY;
  };
  struct List {
    const uint32_t* data;
    uint32_t size;
    const uint32_t* objects;  // per entry, when binned with objects; else nullptr
    const Box* boxes;         // per entry, when binned with boxes; else nullptr
  };
  int chunkCount() const { return chunks_; }
  List list(int chunk, int tile) const {
    const ChunkLists& c = chunkLists_[size_t(chunk)];
    if (c.offsets.empty()) return {nullptr, 0, nullptr, nullptr};
    const uint32_t begin = c.offsets[size_t(tile)];
    return {c.entries.data() + begin, c.offsets[size_t(tile) + 1] - begin,
            c.objects.empty() ? nullptr : c.objects.data() + begin,
            c.boxes.empty() ? nullptr : c.boxes.data() + begin};
  }

 private:
  // A chunk's lists, one after the other in tile order: tile t's is entries[offsets[t],
  // offsets[t+1]). Filled by a counting pass and a placing pass: two flat arrays per chunk instead
  // of a vector per tile and chunk (the same speed on tris 100k×10, far fewer allocations at 8192²
  // rasters).
  struct ChunkLists {
    std::vector<uint32_t> offsets, entries, objects;
    std::vector<Box> boxes;
  };
  int chunks_ = 0, tilesX_ = 0, tiles_ = 0;
  std::vector<ChunkLists> chunkLists_;
};

}  // namespace sv::raster
