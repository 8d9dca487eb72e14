// Segments (SPEC §10, seed 002): the projection of a polygon onto one scan line. Here a segment is
// cut from a triangle's setup record (geometry/setup.h) — the edge functions the tile pipeline
// rasterizes with, their fill rule folded in — so a row's segment holds exactly the pixel centres
// the tile pipeline covers at one sample per pixel, and the two pipelines differ only in how they
// resolve visibility (per-pixel masking or depth there, the priority X-sort here: x_sort.h).
#pragma once

#include <cstdint>

#include "geometry/setup.h"

namespace sv::segments {

// The pixels [xl, xr) of one row that a triangle covers (the seed's X_L … X_R − 1), empty when
// xl ≥ xr.
struct Segment {
  int32_t xl = 0, xr = 0;
  bool empty() const { return xl >= xr; }
};

// The segment of `t` on row y of a raster `width` pixels wide: the pixel centres (px + ½, y + ½)
// with every edge function ≥ 0 (the tile pipeline's point-sampled coverage, bit for bit — the
// same integers), within the record's bounding box and [0, width). Empty off the box's rows.
Segment segmentOf(const geometry::TriangleSetup& t, int y, int width);

// A triangle's segments row after row without a division per edge and row: each edge's bound is
// stepped from the row before as a quotient and remainder (the crossing moves by stepY/stepX a row),
// exactly — the same segments as segmentOf. For triangles of three edges (those clipped by the near
// or far plane have more: segmentOf cuts theirs). 80 bytes, kept by the geometry stage for each
// active triangle instead of reading its 160-byte setup record every row.
class SegmentWalker {
 public:
  static bool fits(const geometry::TriangleSetup& t) { return t.edgeCount == 3; }
  SegmentWalker() = default;
  // At row y of a raster `width` pixels wide, stepping `rowStep` rows at a time (2: one field of
  // an interlaced frame).
  SegmentWalker(const geometry::TriangleSetup& t, int y, int width, int rowStep = 1);
  // The segment of the current row, then on to the next.
  Segment next();

 private:
  // One edge: a left bound ⌈−k/a⌉ (a > 0), a right bound ⌊k/−a⌋ (a < 0), both as q with
  // remainder r ∈ [0, d) and per row q += dq, r += dr (carrying); or (a = 0) the row wholly in or
  // out as k ≥ 0, k += its step.
  struct Edge {
    int64_t q;
    int32_t dq;
    uint32_t r, dr, d;
  };
  static void carry(Edge& w, int carry);
  Edge edges_[3] = {};
  int16_t lo_ = 0, hi_ = -1;  // the box's columns within the raster
  uint8_t kinds_ = 0;         // 2 bits an edge: 0 left, 1 right, 2 horizontal
};

}  // namespace sv::segments
