#include "output/resolve.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "core/check.h"
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace sv::output {

GammaTable GammaTable::srgb() {
  GammaTable g;
  for (int i = 0; i < 65536; ++i) {
    const double l = i / 65535.0;
    // IEC 61966-2-1: linear segment near black, then a 1/2.4 power.
    const double e = l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
    const auto v = static_cast<uint8_t>(std::lround(std::clamp(e, 0.0, 1.0) * 255.0));
    g.table[i] = v;
  }
  return g;
}

GammaTable GammaTable::power(double gamma) {
  GammaTable g;
  for (int i = 0; i < 65536; ++i) {
    const double e = std::pow(i / 65535.0, 1.0 / gamma);
    const auto v = static_cast<uint8_t>(std::lround(std::clamp(e, 0.0, 1.0) * 255.0));
    g.table[i] = v;
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

// Whether every pixel of a one-sample tile holds the same colour: its first block's channels
// each one value, and every block the same as the first (compared 8 bytes at a time, stopping at
// the first difference).
bool uniformTile(const uint16_t* color) {
  using namespace raster;
  for (int ch = 0; ch < 3; ++ch)
    for (int i = 1; i < kBlockPixels; ++i)
      if (color[ch * kBlockPixels + i] != color[ch * kBlockPixels]) return false;
  constexpr int kWords = kColorPerBlock * int(sizeof(uint16_t)) / 8;
  uint64_t first[kWords];
  std::memcpy(first, color, sizeof first);
  for (int block = 1; block < kBlocksPerTileSide * kBlocksPerTileSide; ++block) {
    uint64_t words[kWords];
    std::memcpy(words, color + size_t(block) * kColorPerBlock, sizeof words);
    uint64_t differ = 0;
    for (int i = 0; i < kWords; ++i) differ |= words[i] ^ first[i];
    if (differ) return false;
  }
  return true;
}

}  // namespace

void prepareImage(int width, int height, Image& image) {
  image.width = width;
  image.height = height;
  image.rgb.resize(size_t(image.width) * image.height * 3);
}

void writeImageRow(const uint8_t* src, int n, uint8_t* dst) {
  int i = 0;
#if defined(__SSE2__)
  if ((reinterpret_cast<uintptr_t>(dst) & 15) == 0)
    for (; i + 16 <= n; i += 16)
      _mm_stream_si128(reinterpret_cast<__m128i*>(dst + i),
                       _mm_loadu_si128(reinterpret_cast<const __m128i*>(src + i)));
#endif
  std::copy(src + i, src + n, dst + i);
}

void finishImageRows() {
#if defined(__SSE2__)
  _mm_sfence();
#endif
}

void resolveTile(const uint16_t* color, int tileX, int tileY, const GammaTable& gamma,
                 Image& image) {
  using namespace raster;
  constexpr int g = kBlockPixels, b = 2 * kBlockPixels;
  const int x0 = tileX * kTileSize, y0 = tileY * kTileSize;
  const int w = std::min(kTileSize, image.width - x0), h = std::min(kTileSize, image.height - y0);
  // Each row put together in a buffer, then written out whole (writeImageRow).
  alignas(64) uint8_t row[3 * kTileSize];
  if (w == kTileSize && h == kTileSize && uniformTile(color)) {
    // One colour (a tile of background): one look-up per channel, the same row 64 times.
    for (int x = 0; x < kTileSize; ++x)
      for (int ch = 0; ch < 3; ++ch) row[3 * x + ch] = gamma.table[color[ch * kBlockPixels]];
    for (int y = 0; y < h; ++y) writeImageRow(row, 3 * w, image.pixel(x0, y0 + y));
    finishImageRows();
    return;
  }
  for (int y = 0; y < h; ++y) {
    const uint16_t* src = color + size_t(y >> kBlockLog2) * kBlocksPerTileSide * kColorPerBlock +
                          (y & (kBlockSize - 1)) * kBlockSize;
    for (int x = 0; x < w; x += kBlockSize, src += kColorPerBlock)
      for (int i = 0; i < kBlockSize; ++i) {
        uint8_t* out = row + 3 * (x + i);
        out[0] = gamma.table[src[i]];
        out[1] = gamma.table[src[g + i]];
        out[2] = gamma.table[src[b + i]];
      }
    writeImageRow(row, 3 * w, image.pixel(x0, y0 + y));
  }
  finishImageRows();
}

namespace {

// Calls sink(x, y, mean) for every image pixel of a tile of a raster `factor` times larger than
// the image (supersampling), mean[ch] being the rounded mean of its samples (linear, 16-bit).
template <class Sink>
void forEachBlockMean(const uint16_t* color, int tileX, int tileY, int factor, int width,
                      int height, Sink sink) {
  using raster::FrameBuffer;
  // The tile covers image pixels [x0, x0 + 64/factor) × [y0, …) of the smaller image.
  const int side = raster::kTileSize / factor;
  const int x0 = tileX * side, y0 = tileY * side;
  const int w = std::min(side, width - x0), h = std::min(side, height - y0);
  const uint32_t count = uint32_t(factor * factor);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      uint32_t sum[3] = {0, 0, 0};
      for (int sy = 0; sy < factor; ++sy)
        for (int sx = 0; sx < factor; ++sx)
          for (int ch = 0; ch < 3; ++ch)
            sum[ch] += color[FrameBuffer::colorOffset(u * factor + sx, v * factor + sy, ch)];
      const uint16_t mean[3] = {uint16_t((sum[0] + count / 2) / count),
                                uint16_t((sum[1] + count / 2) / count),
                                uint16_t((sum[2] + count / 2) / count)};
      sink(x0 + u, y0 + v, mean);
    }
}

}  // namespace

void resolveTileLinear(const uint16_t* color, const int32_t* sums, int tileX, int tileY, int factor,
                       int samples, const LinearTarget& t) {
  LinearImage& image = *t.image;
  auto store = [&](int x, int y, const uint16_t* mean) {
    std::copy_n(mean, 3,
                image.rgb.data() + (size_t(t.y + y) * size_t(image.width) + size_t(t.x + x)) * 3);
  };
  if (factor > 1)
    forEachBlockMean(color, tileX, tileY, factor, t.width, t.height, store);
  else
    resolveSampleTileLinear(color, sums, tileX, tileY, samples, t);
}

void tentFilterRows(const LinearImage& linear, const GammaTable& gamma, int rowBegin, int rowEnd,
                    Image& image) {
  const int w = linear.width, h = linear.height;
  auto at = [&](int x, int y, int ch) -> uint32_t {
    x = std::clamp(x, 0, w - 1);
    y = std::clamp(y, 0, h - 1);
    return linear.rgb[(size_t(y) * size_t(w) + size_t(x)) * 3 + size_t(ch)];
  };
  for (int y = rowBegin; y < rowEnd; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* out = image.pixel(x, y);
      for (int ch = 0; ch < 3; ++ch) {
        // SPEC §5 (seed 002): the 3×3 triangle filter, [1 2 1] ⊗ [1 2 1] / 16.
        const uint32_t sum = at(x - 1, y - 1, ch) + 2 * at(x, y - 1, ch) + at(x + 1, y - 1, ch) +
                             2 * at(x - 1, y, ch) + 4 * at(x, y, ch) + 2 * at(x + 1, y, ch) +
                             at(x - 1, y + 1, ch) + 2 * at(x, y + 1, ch) + at(x + 1, y + 1, ch);
        out[ch] = gamma.table[(sum + 8) >> 4];
      }
    }
}

void encodeRows(const LinearImage& linear, const GammaTable& gamma, int rowBegin, int rowEnd,
                Image& image) {
  encodeRect(linear, gamma, 0, rowBegin, linear.width, rowEnd, image);
}

void encodeRect(const LinearImage& linear, const GammaTable& gamma, int x0, int y0, int x1, int y1,
                Image& image) {
  const size_t n = size_t(x1 - x0) * 3;
  for (int y = y0; y < y1; ++y) {
    const uint16_t* src = &linear.rgb[(size_t(y) * size_t(linear.width) + size_t(x0)) * 3];
    uint8_t* out = image.pixel(x0, y);
    for (size_t i = 0; i < n; ++i) out[i] = gamma.table[src[i]];
  }
}

void resolveTile(const uint16_t* color, int tileX, int tileY, int factor, const GammaTable& gamma,
                 Image& image) {
  SV_CHECK(factor == 1 || factor == 2 || factor == 4 || factor == 8 || factor == 16);
  if (factor == 1) return resolveTile(color, tileX, tileY, gamma, image);
  forEachBlockMean(color, tileX, tileY, factor, image.width, image.height,
                   [&](int x, int y, const uint16_t* mean) {
                     uint8_t* out = image.pixel(x, y);
                     for (int ch = 0; ch < 3; ++ch) out[ch] = gamma.table[mean[ch]];
                   });
}

void resolveDebugTile(const uint16_t* color, int tileX, int tileY, DebugPalette palette,
                      Image& image) {
  static constexpr uint8_t kCount[6][3] = {{0, 0, 0},     {30, 60, 220}, {0, 200, 220},
                                           {40, 200, 40}, {240, 220, 0}, {230, 30, 30}};
  static constexpr uint8_t kLevel[7][3] = {{0, 0, 0},     {128, 128, 128}, {30, 60, 220},
                                           {0, 200, 220}, {40, 200, 40},   {240, 220, 0},
                                           {230, 30, 30}};
  const bool count = palette == DebugPalette::count;
  forEachTileRow(color, tileX, tileY, image, [&](uint8_t* out, const uint16_t* src, int n) {
    for (int i = 0; i < n; ++i)
      std::copy_n(count ? kCount[std::min<int>(src[i], 5)] : kLevel[std::min<int>(src[i], 6)], 3,
                  out + 3 * i);
  });
}

}  // namespace sv::output
