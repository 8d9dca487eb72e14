// The video channel's anti-aliasing (SPEC §5, seed 002): the 1×1 box filter by the recipient–donor
// method. In a pixel crossed by the visible segment's boundary, C = C_R·S + C_D·(1 − S): S the area
// of the pixel the visible segment (the recipient) covers, C_D the most likely second colour — the
// donor — taken from one of the pixel's 8 neighbours. Here S is the pixel square's area inside
// every edge of the recipient's triangle (exact for one edge, and for two that do not cross inside
// the pixel), and the donor is the neighbour across the edge that cuts the most off: the one in the
// direction of that edge's outward normal.
//
// The seed's own limit holds and is measured (docs/quality.md): the X-sort keeps one segment per
// pixel centre, so a pixel whose centre lies outside an edge shows its own segment whole, however
// much of it the edge covers — only one side of each edge is blended.
#pragma once

#include <cstdint>

#include "geometry/setup.h"

namespace sv::segments {

// The area of a unit pixel square inside the half-plane n·p ≥ −d (unit normal n = (nx, ny), the
// square's centre at signed distance d inside): 0 … 1, exact.
double halfPlaneArea(double nx, double ny, double d);

// A pixel's recipient: the part S of it inside the triangle, and where its donor is — the
// neighbour (x + dx, y + dy), dx, dy ∈ {−1, 0, 1} (both 0 when S = 1: no donor).
struct Recipient {
  float area = 1;
  int8_t dx = 0, dy = 0;
};

// The recipient of pixel (x, y) in triangle `t` (its setup record: edge functions at pixel
// centres, geometry/setup.h).
Recipient recipientOf(const geometry::TriangleSetup& t, int x, int y);

}  // namespace sv::segments
