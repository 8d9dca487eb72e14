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

SegmentWalker::SegmentWalker(const geometry::TriangleSetup& t, int y, int width, int rowStep) {
  lo_ = int16_t(std::max<int>(t.minX, 0));
  hi_ = int16_t(std::min<int>(t.maxX, width - 1));
  for (int i = 0; i < 3; ++i) {
    const geometry::EdgeFunction& e = t.edges[i];
    const int64_t k = e.c + e.stepY() * y, a = e.stepX(), b = e.stepY() * rowStep;
    Edge& w = edges_[i];
    if (a == 0) {
      // k and its step kept whole: q = k, and the step in (dq, dr) as its high and low halves.
      kinds_ |= uint8_t(2 << (2 * i));
      w.q = k;
      w.dq = int32_t(uint64_t(b) >> 32);
      w.dr = uint32_t(uint64_t(b));
      w.r = w.d = 0;
      continue;
    }
    if (a > 0) {
      // n = −k = q·a − r, 0 ≤ r < a; a row on n −= b: q −= ⌊b/a⌋, r += b mod a (carrying into q).
      w.d = uint32_t(a);
      w.q = ceilDiv(-k, a);
      w.r = uint32_t(w.q * a + k);
      const int64_t qb = floorDiv(b, a);
      w.dq = int32_t(-qb);
      w.dr = uint32_t(b - qb * a);
    } else {
      // n = k = q·d + r, 0 ≤ r < d (d = −a); a row on n += b: q += ⌊b/d⌋, r += b mod d.
      kinds_ |= uint8_t(1 << (2 * i));
      const int64_t d = -a;
      w.d = uint32_t(d);
      w.q = floorDiv(k, d);
      w.r = uint32_t(k - w.q * d);
      const int64_t qb = floorDiv(b, d);
      w.dq = int32_t(qb);
      w.dr = uint32_t(b - qb * d);
    }
  }
}

// r += dr modulo d, q moved by `carry` when it wraps; in 32 bits (r, dr < d < 2^32).
void SegmentWalker::carry(Edge& w, int carry) {
  if (w.r >= w.d - w.dr) {
    w.r -= w.d - w.dr;
    w.q += carry;
  } else {
    w.r += w.dr;
  }
}

Segment SegmentWalker::next() {
  int64_t lo = lo_, hi = hi_;
  for (int i = 0; i < 3; ++i) {
    Edge& w = edges_[i];
    switch ((kinds_ >> (2 * i)) & 3) {
      case 0:  // left: the bound is q; next row q −= ⌊b/a⌋, r += b mod a, a carry lowers q
        lo = std::max(lo, w.q);
        w.q += w.dq;
        carry(w, -1);
        break;
      case 1:  // right
        hi = std::min(hi, w.q);
        w.q += w.dq;
        carry(w, 1);
        break;
      default:  // horizontal
        if (w.q < 0) hi = lo - 1;
        w.q += int64_t((uint64_t(uint32_t(w.dq)) << 32) | w.dr);
        break;
    }
  }
  Segment s;
  if (lo <= hi) s.xl = int32_t(lo), s.xr = int32_t(hi + 1);
  return s;
}

}  // namespace sv::segments
