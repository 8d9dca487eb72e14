// Display stage (SPEC §1 stage 5, §8–§9): the frame buffer's linear colour → display image.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "raster/framebuffer.h"
#include "synthvis/image.h"

namespace sv::output {

// Gamma correction by a look-up table (SPEC §8, seed 002), indexed by the frame buffer's 16-bit
// linear value: one table for all three channels, which share the transfer function (64 KB for the
// resolve's look-ups to keep in cache, not three identical copies).
struct GammaTable {
  std::array<uint8_t, 65536> table;

  static GammaTable srgb();  // the sRGB transfer function (IEC 61966-2-1)
  // A display gamma: encoded = linear^(1/gamma), rounded to 8 bits.
  static GammaTable power(double gamma);
};

// Sizes `image` for a width × height raster; call once per frame before resolving its tiles.
void prepareImage(int width, int height, Image& image);

// Applies the table to one 64×64 tile's colour (laid out as raster/framebuffer.h describes) and
// writes the part of it inside `image` (sized by prepareImage) at tile (tileX, tileY). Tiles write
// disjoint pixels, so different tiles may be resolved on different threads.
// The resolves' way into the image: n bytes of a row put together in a buffer (`row`) written to
// `dst` with non-temporal stores where dst allows (16-byte aligned; the rest plainly). The image's
// lines are not in cache when a tile is resolved, and byte stores into them made the core read
// each line before overwriting it (docs/performance.md, "Resolve"). finishImageRows orders them
// before whatever the thread does next (another thread reads the image once the frame's tiles are
// joined): once per tile.
void writeImageRow(const uint8_t* row, int n, uint8_t* dst);
void finishImageRows();

void resolveTile(const uint16_t* color, int tileX, int tileY, const GammaTable& gamma,
                 Image& image);
// The same for a raster `factor` times larger than the image (factor 2, 4 or 8 divides the tile):
// each image pixel is the rounded mean of its factor × factor samples in linear light.
void resolveTile(const uint16_t* color, int tileX, int tileY, int factor, const GammaTable& gamma,
                 Image& image);

// A tile of N samples per pixel (anti-aliasing; N = 4, 8, 16 or 64, sample planes as
// raster/framebuffer.h describes): each image pixel is the rounded mean of its samples in linear
// light — the 1×1 box filter of SPEC §5. In SIMD lanes: resolve_samples.cpp. With `sums` (the
// tile's colour sums, raster/framebuffer.h) the means come from them and `color` is not read.
void resolveSampleTile(const uint16_t* color, const int32_t* sums, int tileX, int tileY,
                       int samples, const GammaTable& gamma, Image& image);

// Linear colour of a whole frame, 3 × uint16 per pixel, row-major: the box-resolved frame buffer
// that the 3×3 tent filter reads across tile borders.
struct LinearImage {
  int width = 0, height = 0;
  std::vector<uint16_t> rgb;
  void resize(int w, int h) {
    width = w;
    height = h;
    rgb.resize(size_t(w) * size_t(h) * 3);
  }
};

// Where a view's box-resolved tiles go in linear light: the view's width × height pixels, its
// pixel (0, 0) at (x, y) of `image` (sized already, holding the rectangle) — the whole image for
// the tent filter's frame, a rectangle of a display for a sub-frustum cell (render/warped.h).
struct LinearTarget {
  LinearImage* image = nullptr;
  int x = 0, y = 0, width = 0, height = 0;
};
inline LinearTarget wholeOf(LinearImage& image) {
  return {&image, 0, 0, image.width, image.height};
}

// Where a view's tiles go through the gamma table into a rectangle of a larger image (a
// sub-frustum cell's of its display's frame): the view's pixel (0, 0) at (x, y) of `image`, and
// optionally edge-blending weights over the whole image (its width × height, one a pixel),
// applied in linear light before the table — v·alpha + 65535·beta, rounded and clamped, as
// display::applyBlend.
struct ImageTarget {
  Image* image = nullptr;
  int x = 0, y = 0, width = 0, height = 0;
  const float* alpha = nullptr;  // with beta, or both nullptr
  const float* beta = nullptr;
};
// One tile of `samples` samples a pixel (1, 4, 8, 16, 64; `sums` as resolveSampleTile) box-resolved
// into the target: the same bytes as resolveSampleTileLinear, blended, then encodeRect.
void resolveSampleTileTo(const uint16_t* color, const int32_t* sums, int tileX, int tileY,
                         int samples, const GammaTable& gamma, const ImageTarget& target);

// Box-resolves one tile of a view into its target instead of the display image, for any of the
// layouts above: `factor` × `factor` pixels per image pixel (supersampling) or `samples` samples
// per pixel (one of the two is 1); `sums` as resolveSampleTile.
void resolveTileLinear(const uint16_t* color, const int32_t* sums, int tileX, int tileY, int factor,
                       int samples, const LinearTarget& target);
// Its case of factor 1 (samples 1, 4, 8, 16 or 64), in SIMD lanes as resolveSampleTile.
void resolveSampleTileLinear(const uint16_t* color, const int32_t* sums, int tileX, int tileY,
                             int samples, const LinearTarget& target);

// The 3×3 triangle (tent) filter of seed 002 (SPEC §5) over the box-resolved frame, weights
// [1 2 1]ᵀ[1 2 1] / 16 in linear light, edges clamped; then gamma. Writes rows [rowBegin, rowEnd)
// of `image` (sized by prepareImage), so that bands of rows can go to different threads.
void tentFilterRows(const LinearImage& linear, const GammaTable& gamma, int rowBegin, int rowEnd,
                    Image& image);

// The gamma table alone over rows [rowBegin, rowEnd) of a linear frame (one composed of views in
// linear light: distortion correction's cells, edge blending), into `image` (sized by
// prepareImage).
void encodeRows(const LinearImage& linear, const GammaTable& gamma, int rowBegin, int rowEnd,
                Image& image);
// The same over the rectangle [x0, x1) × [y0, y1) alone (a sub-frustum cell's).
void encodeRect(const LinearImage& linear, const GammaTable& gamma, int x0, int y0, int x1, int y1,
                Image& image);

// Debug views: the red channel holds a small number per pixel, shown in false colour. `count`
// (raster::ShadeMode::overdraw): black for 0, then blue, cyan, green, yellow, red for 1, 2, 3,
// 4, ≥5 triangles covering the pixel. `level` (ShadeMode::levels, and the occupancy view): black
// for 0 (nothing), then grey for 1 (a pixel: tested in a 4×4 leaf, or occupied alone), and blue,
// cyan, green, yellow, red for 2…6 (a window of 4, 8, 16, 32, 64 pixels).
enum class DebugPalette { count, level };
void resolveDebugTile(const uint16_t* color, int tileX, int tileY, DebugPalette palette,
                      Image& image);

}  // namespace sv::output
