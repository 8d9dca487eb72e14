// The pixels of a run (SPEC §10: intensity interpolated along the segment; §2: the perspective-
// correct colour as colour/w ÷ 1/w): the tile kernel's Gouraud colour at each pixel centre, in the
// kernel's float operations and order (geometry::planeAtPixel), so the segment pipeline draws the
// tile pipeline's bytes — in SIMD lanes along the row.
#pragma once

#include <cstdint>

#include "geometry/setup.h"

namespace sv::segments {

// Pixels [xa, xb) of row y of triangle `t` as 16-bit linear colour codes, 3 a pixel, into
// rgb[0, 3·(xb − xa)).
void shadeRun(const geometry::TriangleSetup& t, int y, int xa, int xb, uint16_t* rgb);

}  // namespace sv::segments
