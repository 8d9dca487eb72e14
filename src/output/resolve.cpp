#include "output/resolve.h"

#include <cmath>

namespace sv::output {

GammaTables GammaTables::srgb() {
  GammaTables g;
  for (int i = 0; i < 65536; ++i) {
    const double l = i / 65535.0;
    // IEC 61966-2-1: linear segment near black, then a 1/2.4 power.
    const double e = l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
    const auto v = static_cast<uint8_t>(std::lround(std::clamp(e, 0.0, 1.0) * 255.0));
    g.table[0][i] = g.table[1][i] = g.table[2][i] = v;
  }
  return g;
}

namespace {

// Calls fn(rgbOut, tileColor, offset) for every pixel of the raster, where `offset` indexes the
// pixel's red value in its tile's colour array (green and blue follow at +16, +32). One work item
// per tile row: each writes its own rows of the image.
template <class Fn>
void forEachPixel(const raster::FrameBuffer& fb, Image& image, core::ThreadPool& pool, Fn fn) {
  using namespace raster;
  image.width = fb.width();
  image.height = fb.height();
  image.rgb.resize(size_t(image.width) * image.height * 3);
  pool.parallelFor(size_t(fb.tilesY()), [&](size_t ty, int) {
    for (int tx = 0; tx < fb.tilesX(); ++tx) {
      const uint16_t* tile = fb.tileColor(int(ty) * fb.tilesX() + tx);
      const int x0 = tx * kTileSize, y0 = int(ty) * kTileSize;
      const int w = std::min(kTileSize, fb.width() - x0), h = std::min(kTileSize, fb.height() - y0);
      for (int y = 0; y < h; ++y) {
        uint8_t* row = image.pixel(x0, y0 + y);
        const size_t rowBase = size_t(y >> kBlockLog2) * kBlocksPerTileSide * kColorPerBlock +
                               (y & (kBlockSize - 1)) * kBlockSize;
        for (int x = 0; x < w; ++x) {
          const size_t offset =
              rowBase + size_t(x >> kBlockLog2) * kColorPerBlock + (x & (kBlockSize - 1));
          fn(row + x * 3, tile, offset);
        }
      }
    }
  });
}

}  // namespace

void resolve(const raster::FrameBuffer& fb, const GammaTables& gamma, Image& image,
             core::ThreadPool& pool) {
  forEachPixel(fb, image, pool, [&](uint8_t* out, const uint16_t* tile, size_t offset) {
    out[0] = gamma.table[0][tile[offset]];
    out[1] = gamma.table[1][tile[offset + raster::kBlockPixels]];
    out[2] = gamma.table[2][tile[offset + 2 * raster::kBlockPixels]];
  });
}

void resolveOverdraw(const raster::FrameBuffer& fb, Image& image, core::ThreadPool& pool) {
  static constexpr uint8_t kPalette[6][3] = {{0, 0, 0},     {30, 60, 220}, {0, 200, 220},
                                             {40, 200, 40}, {240, 220, 0}, {230, 30, 30}};
  forEachPixel(fb, image, pool, [&](uint8_t* out, const uint16_t* tile, size_t offset) {
    std::copy_n(kPalette[std::min<int>(tile[offset], 5)], 3, out);
  });
}

}  // namespace sv::output
