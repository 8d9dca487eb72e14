// The min/max pyramids of a height table (SPEC §11's max-LOD maps, with the minimum map beside
// them, for tight bounds from both sides).
//
// Level n is the grid itself: its cells (i, j) … (i + 1, j + 1). Level n − 1 holds, for each 2×2
// cells, the smallest and largest height the *interpolated* surface takes over them; level k − 1
// the minimum of the minima and the maximum of the maxima of each 2×2 nodes of level k; level 0 one
// node, the whole map. Level n is not stored: the stored levels n − 1 … 0 cost a third of the
// table's memory at 16 bits a bound, and a ray at the finest stored level solves against the
// surface of at most two cells along its path anyway (caster.h).
//
// The bounds hold for the interpolated surface (issue 29): bilinear interpolation stays within its
// cell's four samples; Catmull–Rom does not. Its 1D weights at t are w₀ = (−t³ + 2t² − t)/2 and
// w₃ = (t³ − t²)/2, both ≤ 0, with w₀ + w₃ = −(t − t²)/2 ≥ −1/8; in 2D the negative weights of the
// tensor product sum to at most 2·(1 + 1/8)·(1/8) = 9/32. So over a cell the surface lies within
// [lo − 9/32·(hi − lo), hi + 9/32·(hi − lo)] for lo, hi the extremes of the 4×4 samples around it
// — the overshoot included, tests/terrain/pyramid_test.cpp checks it by sampling.
#pragma once

#include <cstdint>
#include <vector>

#include "terrain/height_field.h"

namespace sv::terrain {

class Pyramid {
 public:
  Pyramid() = default;
  Pyramid(const HeightField& field, Interpolation interp);

  // n: the grid's level (cells padded to 2^n a side); levels n − 1 … 0 are stored.
  int gridLevel() const { return n_; }
  int cellsX() const { return cellsX_; }
  int cellsY() const { return cellsY_; }
  // Cells per node side at `level` (0 … n).
  int nodeCells(int level) const { return 1 << (n_ - level); }

  struct Range {
    double lo, hi;  // hi < lo: no surface there (beyond the table's footprint)
  };
  // The bounds over nodes [i0, i1] × [j0, j1] of `level` (0 … n − 1), clamped to the footprint.
  Range range(int level, int i0, int i1, int j0, int j1) const;
  // The bounds of node (i, j) of `level`; cell (i, j) itself at level n.
  Range node(int level, int i, int j) const;
  size_t bytes() const;

  // The mean pyramid beside the bounds (the levels of detail a frame draws at a distance, SPEC
  // §11: "the level from the projected size"): level k < n holds the table's samples every
  // 2^(n − k) steps, each the [1 2 1]/4 filter of level k + 1 around it (along both axes, edges
  // repeated), in the table's 16-bit codes; level n is the table. The surface of level k < n is
  // bilinear over its samples, and over a node of level k it stays within the bounds of that node
  // and its eight neighbours (its samples average the table within one node of them).
  struct MeanLevel {
    int width = 0, height = 0;  // samples
    double step = 1;            // grid steps between samples: 2^(n − k)
    const uint16_t* q = nullptr;
    uint16_t code(int i, int j) const { return q[size_t(j) * size_t(width) + size_t(i)]; }
  };
  MeanLevel mean(int level) const {
    if (level >= n_) return {field_->width, field_->height, 1.0, field_->q.data()};
    return {meanW_[size_t(level)], meanH_[size_t(level)], double(nodeCells(level)),
            means_[size_t(level)].data()};
  }

  // The packets' skip map beside each level of detail (packet_walk.h): for level k (0 … n, n the
  // table), the highest of its samples over each square of kTopCells × kTopCells of its cells —
  // the top of that square's bilinear surface, exactly, in the level's own codes; for the table's
  // own bicubic surface, the highest of its cells' tops (cellTops). A packet's lane passes a
  // square whose top its ray stays above at once instead of cell by cell. Node (I, J) covers cells
  // kTopCells·I … kTopCells·(I + 1) − 1 (clamped to the level's cells); one code of padding after
  // the last node, for 32-bit reads. A top of 65535 (kNoTop) bounds nothing: the bicubic surface
  // may overshoot the codes' range.
  static constexpr int kTopShift = 2;
  static constexpr int kTopCells = 1 << kTopShift;
  struct TopLevel {
    int width = 0, height = 0;  // nodes
    const uint16_t* top = nullptr;
  };
  TopLevel tops(int level) const;
  static constexpr uint16_t kNoTop = 65535;
  // With bicubic interpolation: per cell of the table, the top of its patch's Bézier hull
  // (bezierTop, rounded up; kNoTop where it reaches beyond the codes) — the bound a packet walks
  // the table's bicubic surface by (packet_walk.h). Empty (top null) for bilinear.
  TopLevel cellTops() const {
    return {cellsX_, cellsY_, cellTops_.empty() ? nullptr : cellTops_.data()};
  }

 private:
  struct Bound {
    uint16_t lo, hi;  // codes of boundOffset_ + boundScale_·code, rounded outward
  };
  int n_ = 0, cellsX_ = 0, cellsY_ = 0;
  double boundOffset_ = 0, boundScale_ = 1;
  std::vector<std::vector<Bound>> levels_;    // levels_[k]: 2^k × 2^k nodes, k = 0 … n − 1
  std::vector<int> sideX_, sideY_;            // per level: the nodes over the footprint
  std::vector<std::vector<uint16_t>> means_;  // means_[k], k = 0 … n − 1 (MeanLevel)
  std::vector<int> meanW_, meanH_;
  std::vector<std::vector<uint16_t>> tops_;  // tops_[k], k = 0 … n (TopLevel)
  std::vector<int> topW_, topH_;
  std::vector<uint16_t> cellTops_;  // cellsX_ × cellsY_ and one of padding (bicubic only)
  const HeightField* field_ = nullptr;
  Interpolation interp_ = Interpolation::bilinear;
  Range cell(int i, int j) const;  // level n, computed from the table
  void buildTops();
};

}  // namespace sv::terrain
