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

}  // namespace sv::segments
