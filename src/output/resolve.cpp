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

// Calls fn(x, y, rgbOut) for every pixel, one work item per tile row (each writes its own rows).
template <class Fn>
void forEachPixel(const raster::FrameBuffer& fb, Image& image, core::ThreadPool& pool, Fn fn) {
  image.width = fb.width();
  image.height = fb.height();
  image.rgb.resize(size_t(image.width) * image.height * 3);
  pool.parallelFor(size_t(fb.tilesY()), [&](size_t ty, int) {
    const int y0 = int(ty) * raster::kTileSize;
    const int y1 = std::min(y0 + raster::kTileSize, fb.height());
    for (int y = y0; y < y1; ++y) {
      uint8_t* row = image.pixel(0, y);
      for (int x = 0; x < fb.width(); ++x) fn(x, y, row + x * 3);
    }
  });
}

}  // namespace

void resolve(const raster::FrameBuffer& fb, const GammaTables& gamma, Image& image,
             core::ThreadPool& pool) {
  forEachPixel(fb, image, pool, [&](int x, int y, uint8_t* out) {
    for (int ch = 0; ch < 3; ++ch) out[ch] = gamma.table[ch][fb.colorAt(x, y, ch)];
  });
}

void resolveOverdraw(const raster::FrameBuffer& fb, Image& image, core::ThreadPool& pool) {
  static constexpr uint8_t kPalette[6][3] = {{0, 0, 0},     {30, 60, 220}, {0, 200, 220},
                                             {40, 200, 40}, {240, 220, 0}, {230, 30, 30}};
  forEachPixel(fb, image, pool, [&](int x, int y, uint8_t* out) {
    const int n = std::min<int>(fb.colorAt(x, y, 0), 5);
    std::copy_n(kPalette[n], 3, out);
  });
}

}  // namespace sv::output
