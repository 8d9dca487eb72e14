// Display stage (SPEC §1 stage 5, §8–§9): the frame buffer's linear colour → display image.
#pragma once

#include <array>
#include <cstdint>

#include "raster/framebuffer.h"
#include "synthvis/image.h"

namespace sv::output {

// Gamma correction by three look-up tables, one per channel (SPEC §8, seed 002), indexed by the
// frame buffer's 16-bit linear value.
struct GammaTables {
  std::array<std::array<uint8_t, 65536>, 3> table;

  static GammaTables srgb();  // the sRGB transfer function (IEC 61966-2-1)
  // A display gamma: encoded = linear^(1/gamma), rounded to 8 bits.
  static GammaTables power(double gamma);
};

// Sizes `image` for a width × height raster; call once per frame before resolving its tiles.
void prepareImage(int width, int height, Image& image);

// Applies the tables to one 64×64 tile's colour (laid out as raster/framebuffer.h describes) and
// writes the part of it inside `image` (sized by prepareImage) at tile (tileX, tileY). Tiles write
// disjoint pixels, so different tiles may be resolved on different threads.
void resolveTile(const uint16_t* color, int tileX, int tileY, const GammaTables& gamma,
                 Image& image);
// The same for a raster `factor` times larger than the image (factor 2, 4 or 8 divides the tile):
// each image pixel is the rounded mean of its factor × factor samples in linear light.
void resolveTile(const uint16_t* color, int tileX, int tileY, int factor, const GammaTables& gamma,
                 Image& image);

// For the overdraw count (raster::ShadeMode::overdraw): a false-colour image, black for 0, then
// blue, cyan, green, yellow, red for 1, 2, 3, 4, ≥5 triangles covering the pixel.
void resolveOverdrawTile(const uint16_t* color, int tileX, int tileY, Image& image);

}  // namespace sv::output
