// Per-tile lists of a pass's items (light splats, line strips): each tile's list holds copies of
// the items that reach it, in item order, so that a tile reads its items in one run and what a
// tile gets never depends on the thread count. Built from the items in chunks — fixed by the item
// count, never the thread count — in parallel: every chunk makes its items and counts them per
// tile, a prefix sum
// over (tile, chunk) gives where each chunk's items for each tile go (a counting sort), and every
// chunk copies its items there.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/thread_pool.h"

namespace sv::raster {

template <class Item>
class TileLists {
 public:
  // produce(c, chunks[c]) makes chunk c's items (in parallel; `chunks` sized by the caller, the
  // items in order chunk by chunk); forTiles(item, f) calls f(tile index) for every tile of the
  // `tiles` the item reaches.
  template <class Produce, class ForTiles>
  void build(std::vector<std::vector<Item>>& chunks, size_t tiles, core::ThreadPool& pool,
             Produce&& produce, ForTiles&& forTiles) {
    const size_t n = chunks.size();
    at_.assign(n * tiles, 0);
    pool.parallelFor(n, [&](size_t c, int) {
      produce(c, chunks[c]);
      for (const Item& item : chunks[c]) forTiles(item, [&](size_t t) { ++at_[c * tiles + t]; });
    });
    start_.assign(tiles + 1, 0);
    uint32_t at = 0;
    for (size_t t = 0; t < tiles; ++t) {
      start_[t] = at;
      for (size_t c = 0; c < n; ++c) {
        const uint32_t count = at_[c * tiles + t];
        at_[c * tiles + t] = at;
        at += count;
      }
    }
    start_[tiles] = at;
    items_.resize(at);
    pool.parallelFor(n, [&](size_t c, int) {
      for (const Item& item : chunks[c])
        forTiles(item, [&](size_t t) { items_[at_[c * tiles + t]++] = item; });
    });
  }

  std::span<const Item> tile(size_t t) const {
    return {items_.data() + start_[t], items_.data() + start_[t + 1]};
  }
  // Where tile t's items start among every tile's (for arrays kept beside the lists), and how many
  // items there are in all.
  size_t first(size_t t) const { return start_[t]; }
  size_t size() const { return items_.size(); }

 private:
  std::vector<uint32_t> at_;     // per chunk and tile: its count, then where its items go
  std::vector<uint32_t> start_;  // per tile: where its items start in items_
  std::vector<Item> items_;      // every tile's items, in item order within a tile
};

}  // namespace sv::raster
