// Adding a splat's weights to a tile's colour samples a 4×4 block at a time (raster/framebuffer.h's
// layout: a block's sample plane is 16 R, 16 G, 16 B values), in SIMD lanes (Highway, dispatched
// per call). The same arithmetic as one pixel at a time: each sample gains
// ⌊rgb · kx · ky + ½⌋, saturating at 65535.
#pragma once

#include <cstdint>

namespace sv::lights {

// The part of a splat that lies in one tile: tile-local pixels [x0, x1] × [y0, y1] (inclusive),
// the kernel's column weights kx[x − kernelX] and row weights ky[y − kernelY] (tile-local origins)
// and a weight-1 pixel's additions.
struct SplatInTile {
  int x0 = 0, x1 = -1, y0 = 0, y1 = -1;
  const float* kx = nullptr;
  const float* ky = nullptr;
  int kernelX = 0, kernelY = 0;
  float rgb[3] = {};
};

// Adds the splat to every sample of its pixels in the tile's colour (`samples` planes a block).
void addSplat(uint16_t* tileColor, int samples, const SplatInTile& s);

}  // namespace sv::lights
