// One channel drawn by several processes together (issue 36, SPEC §3.4: seed 000's picture split
// over a matrix of processors as sparse rasters; docs/cluster.md): which 64×64 tiles a process
// draws, and the transport its parts assemble the image through.
#pragma once

#include <cstdint>
#include <vector>

#include "synthvis/result.h"

namespace sv {

// How the parts of a shared channel exchange what they drew — the caller's transport (the
// cluster's MPI, cluster/cluster.h; a test's threads). Every part calls each function the same
// number of times in the same order. An error (a part that never answered) ends the frame.
class TileExchange {
 public:
  virtual ~TileExchange() = default;
  // Every other part's bytes to part 0: on part 0, `all[p]` (p ≥ 1), sized by the caller to
  // part p's byte count, receives part p's `mine` (part 0's own `mine` and `all[0]` are not
  // used); on the others, `all` is not touched.
  virtual Status gather(const std::vector<uint8_t>& mine,
                        std::vector<std::vector<uint8_t>>& all) = 0;
  // The element-wise maximum of every part's `values` (all of one length), on every part.
  virtual Status maxAll(std::vector<float>& values) = 0;
};

// Part `part` of `parts` draws the tiles (tx, ty) of the raster with (tx + ty) mod parts = part:
// interleaved on the diagonals — a checkerboard for two parts — so that every part gets some of
// every region of the picture and the load balances (seed 000's sparse rasters). Part 0
// assembles the image.
struct TileShare {
  int parts = 1, part = 0;
  TileExchange* exchange = nullptr;  // with parts > 1

  bool shared() const { return parts > 1; }
  bool owns(int tileX, int tileY) const { return parts <= 1 || (tileX + tileY) % parts == part; }
};

}  // namespace sv
