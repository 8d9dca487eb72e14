// Based on: SPEC §10 (seed 002: a segment is a polygon's intersection with a scan line, covering
// X_L … X_R − 1); geometry/setup.h (the edge functions and their fill rule, evaluated at pixel
// centres exactly as the tile pipeline's point sampling does).
#include "segments/segments.h"

#include <algorithm>
#include <cmath>

namespace sv::segments {
namespace {

// ⌈n / d⌉ for d > 0, exactly: the quotient in double (|n| < 2^53 here, so it is within one of the
// true one), then corrected in integers — a double division instead of a 64-bit integer one.
int64_t ceilDiv(int64_t n, int64_t d) {
  int64_t q = int64_t(std::ceil(double(n) / double(d)));
  if (q * d < n) ++q;
  if ((q - 1) * d >= n) --q;
  return q;
}
// ⌊n / d⌋ for d > 0, likewise.
int64_t floorDiv(int64_t n, int64_t d) {
  int64_t q = int64_t(std::floor(double(n) / double(d)));
  if (q * d > n) --q;
  if ((q + 1) * d <= n) ++q;
  return q;
}

}  // namespace

Segment segmentOf(const geometry::TriangleSetup& t, int y, int width) {
  Segment s;
  if (y < t.minY || y > t.maxY) return s;
  // Each edge e(px) = k + stepX·px ≥ 0, k = c + stepY·y, bounds px on one side (stepX ≠ 0) or
  // holds for the whole row or none of it (stepX = 0).
  int64_t lo = std::max<int64_t>(t.minX, 0), hi = std::min<int64_t>(t.maxX, width - 1);
  for (int i = 0; i < t.edgeCount && lo <= hi; ++i) {
    const geometry::EdgeFunction& e = t.edges[i];
    const int64_t k = e.c + e.stepY() * y, a = e.stepX();
    if (a == 0) {
      if (k < 0) hi = lo - 1;
    } else if (a > 0) {
      lo = std::max(lo, ceilDiv(-k, a));
    } else {
      hi = std::min(hi, floorDiv(k, -a));
    }
  }
  if (lo > hi) return s;
  s.xl = int32_t(lo);
  s.xr = int32_t(hi + 1);
  return s;
}

}  // namespace sv::segments
