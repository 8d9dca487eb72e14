// Based on: SPEC §10 (seed 002: a segment is a polygon's intersection with a scan line, covering
// X_L … X_R − 1); geometry/setup.h (the edge functions and their fill rule, evaluated at pixel
// centres exactly as the tile pipeline's point sampling does).
#include "segments/segments.h"

#include <algorithm>
#include <limits>

namespace sv::segments {
namespace {

// ⌊n / d⌋ and ⌈n / d⌉ for d > 0 (C++ division truncates toward zero).
int64_t floorDiv(int64_t n, int64_t d) { return n >= 0 ? n / d : -((-n + d - 1) / d); }
int64_t ceilDiv(int64_t n, int64_t d) { return n >= 0 ? (n + d - 1) / d : -(-n / d); }

}  // namespace

Segment segmentOf(const geometry::TriangleSetup& t, int y, int width) {
  Segment s;
  if (y < t.minY || y > t.maxY) return s;
  // Each edge e(px) = k + stepX·px ≥ 0, k = c + stepY·y, bounds px on one side (stepX ≠ 0) or
  // holds for the whole row or none of it (stepX = 0).
  int64_t lo = std::max<int64_t>(t.minX, 0), hi = std::min<int64_t>(t.maxX, width - 1);
  double exactLo = -std::numeric_limits<double>::infinity();
  double exactHi = std::numeric_limits<double>::infinity();
  for (int i = 0; i < t.edgeCount && lo <= hi; ++i) {
    const geometry::EdgeFunction& e = t.edges[i];
    const int64_t k = e.c + e.stepY() * y, a = e.stepX();
    if (a == 0) {
      if (k < 0) hi = lo - 1;
      continue;
    }
    // The continuous crossing of the centre line: e = 0 at px = −k/a pixel centres, which is the
    // pixel position −k/a + ½ (the fill rule's half step aside).
    const double cross = -double(k) / double(a) + 0.5;
    if (a > 0) {
      lo = std::max(lo, ceilDiv(-k, a));
      exactLo = std::max(exactLo, cross);
    } else {
      hi = std::min(hi, floorDiv(k, -a));
      exactHi = std::min(exactHi, cross);
    }
  }
  if (lo > hi) return s;
  s.xl = int32_t(lo);
  s.xr = int32_t(hi + 1);
  // Clamped to the covered pixels' squares: the box and the raster edge cut the span too.
  s.exactLeft = float(std::clamp(exactLo, double(s.xl) - 0.5, double(s.xl) + 0.5));
  s.exactRight = float(std::clamp(exactHi, double(s.xr) - 0.5, double(s.xr) + 0.5));
  return s;
}

}  // namespace sv::segments
