// Display stage (SPEC §1 stage 5, §8–§9): the frame buffer's linear colour → display image.
#pragma once

#include <array>
#include <cstdint>

#include "core/thread_pool.h"
#include "raster/framebuffer.h"
#include "synthvis/image.h"

namespace sv::output {

// Gamma correction by three look-up tables, one per channel (SPEC §8, seed 002), indexed by the
// frame buffer's 16-bit linear value.
struct GammaTables {
  std::array<std::array<uint8_t, 65536>, 3> table;

  static GammaTables srgb();  // the sRGB transfer function (IEC 61966-2-1)
};

// Crops the frame buffer to its raster, applies the tables and writes `image` (resized).
void resolve(const raster::FrameBuffer& fb, const GammaTables& gamma, Image& image,
             core::ThreadPool& pool);

// For the overdraw count (raster::ShadeMode::overdraw): a false-colour image, black for 0, then
// blue, cyan, green, yellow, red for 1, 2, 3, 4, ≥5 triangles covering the pixel.
void resolveOverdraw(const raster::FrameBuffer& fb, Image& image, core::ThreadPool& pool);

}  // namespace sv::output
