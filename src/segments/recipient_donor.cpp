// Based on: SPEC §5 (seed 002: the 1×1 box filter by the recipient–donor method,
// C = C_R·S + C_D·(1 − S), the donor from one of the 8 neighbours); the area of a square cut by a
// line as a function of its distance from the centre (the box filter of an edge).
#include "segments/recipient_donor.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace sv::segments {

double halfPlaneArea(double nx, double ny, double d) {
  // With p ≥ q the larger and smaller of |nx|, |ny|: the line crosses the square's two sides
  // across p while |d| ≤ (p − q)/2 (area linear in d), cuts a corner triangle of legs
  // t/q and t/p while (p − q)/2 < |d| < (p + q)/2, t = (p + q)/2 − |d|, and misses beyond.
  const double p = std::max(std::fabs(nx), std::fabs(ny)),
               q = std::min(std::fabs(nx), std::fabs(ny));
  const double half = 0.5 * (p + q), a = std::fabs(d);
  if (a >= half) return d > 0 ? 1.0 : 0.0;
  if (a <= 0.5 * (p - q)) return 0.5 + d / p;
  const double t = half - a, corner = t * t / (2 * p * q);
  return d > 0 ? 1.0 - corner : corner;
}

Recipient recipientOf(const geometry::TriangleSetup& t, int x, int y) {
  Recipient r;
  double outside = 0, most = 0;
  for (int i = 0; i < t.edgeCount; ++i) {
    const geometry::EdgeFunction& e = t.edges[i];
    const int64_t v = e.c + e.stepX() * x + e.stepY() * y;
    // The edge misses the square (on its inside) when v ≥ 128·(|a| + |b|): the distance
    // v / (256·|n|) at least half the square's extent (|a| + |b|) / (2·|n|) across the edge.
    if (v >= 128 * (std::llabs(e.a) + std::llabs(e.b))) continue;
    const double len = std::hypot(double(e.a), double(e.b));
    if (len == 0) continue;
    const double nx = e.a / len, ny = e.b / len;
    const double cut = 1 - halfPlaneArea(nx, ny, double(v) / (256.0 * len));
    outside += cut;
    if (cut > most) {
      // The donor lies across this edge: its outward normal −n, to the nearest of 8 directions
      // (a component counts beyond sin 22.5°).
      most = cut;
      constexpr double kSin22 = 0.38268343236508978;
      r.dx = int8_t(-nx > kSin22 ? 1 : -nx < -kSin22 ? -1 : 0);
      r.dy = int8_t(-ny > kSin22 ? 1 : -ny < -kSin22 ? -1 : 0);
    }
  }
  r.area = float(std::clamp(1 - outside, 0.0, 1.0));
  if (r.area == 1) r.dx = r.dy = 0;
  return r;
}

}  // namespace sv::segments

namespace sv::segments {

void recipientDonorRows(const SortedFrame& f, int rowBegin, int rowEnd, uint16_t* out) {
  const size_t w = size_t(f.width);
  for (int y = rowBegin; y < rowEnd; ++y)
    for (int x = 0; x < f.width; ++x) {
      const size_t i = size_t(y) * w + size_t(x);
      const uint32_t r = f.visible[i];
      float cut = 0;
      int dx = 0, dy = 0;
      if (r != f.unsorted) {
        if (r != f.background) {
          const Recipient own = recipientOf(f.setups[r], x, y);
          cut = 1 - own.area;
          dx = own.dx;
          dy = own.dy;
        }
        // The triangles other than the recipient shown at the neighbours: the area each covers of
        // this pixel, those in front of the recipient cutting it off.
        uint32_t seen[8];
        int n = 0;
        float front = 0, others = 0, most = 0;
        int mx = 0, my = 0;
        for (int ny = std::max(y - 1, 0); ny <= std::min(y + 1, f.height - 1); ++ny)
          for (int nx = std::max(x - 1, 0); nx <= std::min(x + 1, f.width - 1); ++nx) {
            const uint32_t t = f.visible[size_t(ny) * w + size_t(nx)];
            if (t == r || t >= f.background || std::find(seen, seen + n, t) != seen + n) continue;
            seen[n++] = t;
            const float a = recipientOf(f.setups[t], x, y).area;
            others += a;
            if (t < r) front += a;
            if (a > most) most = a, mx = nx - x, my = ny - y;
          }
        cut = std::min(std::max(cut, front), 1.0f);
        // The donor: the neighbouring triangle that covers the most of the pixel, unless more of
        // the cut-off part is claimed by none of them — then the neighbour across the recipient's
        // edge (the background, or what lies behind).
        if (most > 0 && (most >= cut - others || (dx == 0 && dy == 0))) dx = mx, dy = my;
      }
      const size_t j = size_t(y + dy) * w + size_t(x + dx);
      const bool blend = cut > 0 && (dx != 0 || dy != 0) && x + dx >= 0 && x + dx < f.width &&
                         y + dy >= 0 && y + dy < f.height && f.visible[j] != f.unsorted;
      for (int c = 0; c < 3; ++c) {
        const uint16_t own = f.rgb[3 * i + size_t(c)];
        out[3 * i + size_t(c)] =
            blend ? uint16_t(float(own) * (1 - cut) + float(f.rgb[3 * j + size_t(c)]) * cut + 0.5f)
                  : own;
      }
    }
}

}  // namespace sv::segments
