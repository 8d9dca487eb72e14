#include "output/resolve.h"

#include <algorithm>
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

GammaTables GammaTables::power(double gamma) {
  GammaTables g;
  for (int i = 0; i < 65536; ++i) {
    const double e = std::pow(i / 65535.0, 1.0 / gamma);
    const auto v = static_cast<uint8_t>(std::lround(std::clamp(e, 0.0, 1.0) * 255.0));
    g.table[0][i] = g.table[1][i] = g.table[2][i] = v;
  }
  return g;
}

namespace {

// Calls fn(rgbOut, src, n) for every row of 4 pixels of a block of the tile that lies (n of them)
// inside the image; src points at the row's red values in the tile's planar colour array (green
// and blue follow at +16 and +32).
template <class Fn>
void forEachTileRow(const uint16_t* color, int tileX, int tileY, Image& image, Fn fn) {
  using namespace raster;
  const int x0 = tileX * kTileSize, y0 = tileY * kTileSize;
  const int w = std::min(kTileSize, image.width - x0), h = std::min(kTileSize, image.height - y0);
  for (int y = 0; y < h; ++y) {
    uint8_t* row = image.pixel(x0, y0 + y);
    const uint16_t* src = color + size_t(y >> kBlockLog2) * kBlocksPerTileSide * kColorPerBlock +
                          (y & (kBlockSize - 1)) * kBlockSize;
    for (int x = 0; x < w; x += kBlockSize, src += kColorPerBlock, row += 3 * kBlockSize)
      fn(row, src, std::min(kBlockSize, w - x));
  }
}

}  // namespace

void prepareImage(int width, int height, Image& image) {
  image.width = width;
  image.height = height;
  image.rgb.resize(size_t(image.width) * image.height * 3);
}

void resolveTile(const uint16_t* color, int tileX, int tileY, const GammaTables& gamma,
                 Image& image) {
  constexpr int g = raster::kBlockPixels, b = 2 * raster::kBlockPixels;
  forEachTileRow(color, tileX, tileY, image, [&](uint8_t* out, const uint16_t* src, int n) {
    for (int i = 0; i < n; ++i) {
      out[3 * i] = gamma.table[0][src[i]];
      out[3 * i + 1] = gamma.table[1][src[g + i]];
      out[3 * i + 2] = gamma.table[2][src[b + i]];
    }
  });
}

void resolveTile(const uint16_t* color, int tileX, int tileY, int factor, const GammaTables& gamma,
                 Image& image) {
  if (factor == 1) return resolveTile(color, tileX, tileY, gamma, image);
  using raster::FrameBuffer;
  // The tile covers image pixels [x0, x0 + 64/factor) × [y0, …) of the smaller image.
  const int side = raster::kTileSize / factor;
  const int x0 = tileX * side, y0 = tileY * side;
  const int w = std::min(side, image.width - x0), h = std::min(side, image.height - y0);
  const uint32_t count = uint32_t(factor * factor);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      uint32_t sum[3] = {0, 0, 0};
      for (int sy = 0; sy < factor; ++sy)
        for (int sx = 0; sx < factor; ++sx)
          for (int ch = 0; ch < 3; ++ch)
            sum[ch] += color[FrameBuffer::colorOffset(u * factor + sx, v * factor + sy, ch)];
      uint8_t* out = image.pixel(x0 + u, y0 + v);
      for (int ch = 0; ch < 3; ++ch) out[ch] = gamma.table[size_t(ch)][(sum[ch] + count / 2) / count];
    }
}

void resolveOverdrawTile(const uint16_t* color, int tileX, int tileY, Image& image) {
  static constexpr uint8_t kPalette[6][3] = {{0, 0, 0},     {30, 60, 220}, {0, 200, 220},
                                             {40, 200, 40}, {240, 220, 0}, {230, 30, 30}};
  forEachTileRow(color, tileX, tileY, image, [&](uint8_t* out, const uint16_t* src, int n) {
    for (int i = 0; i < n; ++i) std::copy_n(kPalette[std::min<int>(src[i], 5)], 3, out + 3 * i);
  });
}

}  // namespace sv::output
