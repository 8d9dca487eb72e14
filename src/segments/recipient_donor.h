// The video channel's anti-aliasing (SPEC §5, seed 002): the 1×1 box filter by the recipient–donor
// method. In a pixel crossed by the visible segment's boundary, C = C_R·S + C_D·(1 − S): S the area
// of the pixel the visible segment (the recipient) covers, C_D the most likely second colour — the
// donor — taken from one of the pixel's 8 neighbours.
//
// The recipient is the triangle the X-sort shows at the pixel's centre. What of the pixel it does
// not own is cut off two ways: by its own edges (the area outside them), and by triangles in front
// of it that the X-sort shows at neighbouring pixels (the area each covers of this pixel); the
// larger of the two is taken (a shared edge between the recipient and a triangle in front is
// both). The donor is the neighbouring triangle that covers the most of the pixel — unless more of
// the cut-off part is claimed by none of them, as where the background or something behind lies
// across the recipient's edge: then the neighbour across the edge that cuts the most. So a single
// edge between two triangles, or a triangle and the background, is blended on both of its sides —
// the box filter's image of it. What the X-sort loses is lost here too (SPEC §5, the seed's stated
// limit): a triangle that holds no pixel centre near the pixel, and any third colour in it, since
// one donor stands for the whole cut-off part (docs/quality.md measures it).
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
// centres, geometry/setup.h): the area inside every edge — exact for one edge, and for two that do
// not cross inside the pixel — and the donor across the edge that cuts the most off.
Recipient recipientOf(const geometry::TriangleSetup& t, int x, int y);

// A frame as the sorter left it: per pixel the number of the triangle visible at its centre
// (`visible`, row-major; `background` for none, `unsorted` for a repeated line's pixels, which are
// left as they are and give no donor), the triangles' setup records by number, and the colours
// (3 × uint16 linear per pixel). The recipient–donor filter over rows [rowBegin, rowEnd) into
// `out` (the same layout), so that bands of rows can go to different threads.
struct SortedFrame {
  int width = 0, height = 0;
  const uint32_t* visible = nullptr;
  uint32_t background = 0, unsorted = 0;  // the triangles are numbered below background
  const geometry::TriangleSetup* setups = nullptr;
  const uint16_t* rgb = nullptr;
};
void recipientDonorRows(const SortedFrame& frame, int rowBegin, int rowEnd, uint16_t* out);

}  // namespace sv::segments
