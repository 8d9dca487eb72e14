// The resolve of anti-aliased tiles (N sample planes per 4×4 block, raster/framebuffer.h): each
// pixel the rounded mean of its samples in linear light, the 1×1 box filter of SPEC §5, then gamma.
// The plane sums run in SIMD lanes (Highway, dispatched once per tile); the table look-ups per
// pixel stay scalar, into a row buffer written to the image whole (writeImageRow).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "output/resolve_samples.cpp"
#include <algorithm>
#include <bit>
#include <cmath>

#include "core/check.h"
#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"
#include "output/resolve.h"
#include "synthvis/sample_counts.h"

HWY_BEFORE_NAMESPACE();
namespace sv::output {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Writes `cols` pixels of one block row from the means (red at mean[p], green at mean[16 + p],
// blue at mean[32 + p]). Restrict-qualified: otherwise every byte store may alias the means and
// the table and forces their reload.
HWY_INLINE void StoreBlockRow(uint8_t* HWY_RESTRICT dst, const uint16_t* HWY_RESTRICT mean,
                              int cols, const uint8_t* HWY_RESTRICT table) {
  for (int p = 0; p < cols; ++p) {
    dst[3 * p] = table[mean[p]];
    dst[3 * p + 1] = table[mean[raster::kBlockPixels + p]];
    dst[3 * p + 2] = table[mean[2 * raster::kBlockPixels + p]];
  }
}

// The means of a tile's pixels, a row of blocks at a time (every block's, then the `rows` image
// rows of that block row handed to writeRows(by, rows, blocksX, mean)): in lanes, from the sample
// planes or from the sums.
template <class WriteRows>
HWY_INLINE void ForEachMeanBlockRow(const uint16_t* color, const int32_t* sums, int w, int h,
                                    int samples, WriteRows&& writeRows) {
  using namespace raster;
  const hn::CappedTag<int32_t, kBlockPixels> d32;
  const hn::Rebind<uint16_t, decltype(d32)> d16;
  const size_t n = hn::Lanes(d32);
  const int shift = std::countr_zero(unsigned(samples));  // samples is a power of two
  const auto half = hn::Set(d32, samples / 2);
  alignas(64) uint16_t mean[kBlocksPerTileSide][kColorPerBlock];
  const int blocksX = (w + kBlockSize - 1) / kBlockSize;
  for (int by = 0; by < h; by += kBlockSize) {
    for (int b = 0; b < blocksX; ++b) {
      const size_t index = size_t((by >> kBlockLog2) * kBlocksPerTileSide + b);
      if (sums) {  // the sums of the planes, kept as they were drawn
        const int32_t* sum = sums + index * kColorPerBlock;
        for (size_t i = 0; i < size_t(kColorPerBlock); i += n)
          hn::Store(
              hn::DemoteTo(d16, hn::ShiftRightSame(hn::Add(hn::LoadU(d32, sum + i), half), shift)),
              d16, mean[b] + i);
        continue;
      }
      const uint16_t* block = color + index * samples * kColorPerBlock;
      for (size_t i = 0; i < size_t(kColorPerBlock); i += n) {
        auto sum = hn::PromoteTo(d32, hn::LoadU(d16, block + i));
        for (int s = 1; s < samples; ++s)
          sum = hn::Add(sum, hn::PromoteTo(d32, hn::LoadU(d16, block + s * kColorPerBlock + i)));
        hn::Store(hn::DemoteTo(d16, hn::ShiftRightSame(hn::Add(sum, half), shift)), d16,
                  mean[b] + i);
      }
    }
    writeRows(by, std::min(kBlockSize, h - by), blocksX, mean);
  }
}

void ResolveSampleTile(const uint16_t* color, const int32_t* sums, int tileX, int tileY,
                       int samples, const GammaTable& gamma, Image& image) {
  using namespace raster;
  const int x0 = tileX * kTileSize, y0 = tileY * kTileSize;
  const int w = std::min(kTileSize, image.width - x0), h = std::min(kTileSize, image.height - y0);
  uint8_t* const rgb = image.rgb.data();
  const size_t stride = size_t(image.width) * 3;
  // Each block row's image rows left to right (writing block by block, four rows at once, was
  // slower: the image rows fill sequentially).
  alignas(64) uint8_t row[3 * kTileSize];  // an image row, written out whole (writeImageRow)
  ForEachMeanBlockRow(
      color, sums, w, h, samples,
      [&](int by, int rows, int blocksX, const uint16_t(*mean)[kColorPerBlock]) {
        for (int py = 0; py < rows; ++py) {
          for (int b = 0; b < blocksX; ++b)
            StoreBlockRow(row + 3 * kBlockSize * b, mean[b] + py * kBlockSize,
                          std::min(kBlockSize, w - b * kBlockSize), gamma.table.data());
          writeImageRow(row, 3 * w, rgb + size_t(y0 + by + py) * stride + size_t(x0) * 3);
        }
      });
  finishImageRows();
}

// The same means into a linear-light image, interleaved RGB, no table; each row gathered, then
// copied whole (plainly: a sub-frustum cell's rows are short and start anywhere).
void ResolveSampleTileLinear(const uint16_t* color, const int32_t* sums, int tileX, int tileY,
                             int samples, const LinearTarget& t) {
  using namespace raster;
  const int w = std::min(kTileSize, t.width - tileX * kTileSize);
  const int h = std::min(kTileSize, t.height - tileY * kTileSize);
  const int x0 = t.x + tileX * kTileSize, y0 = t.y + tileY * kTileSize;  // in the image
  uint16_t* const rgb = t.image->rgb.data();
  const size_t stride = size_t(t.image->width) * 3;
  alignas(64) uint16_t row[3 * kTileSize];
  ForEachMeanBlockRow(color, sums, w, h, samples,
                      [&](int by, int rows, int blocksX, const uint16_t(*mean)[kColorPerBlock]) {
                        for (int py = 0; py < rows; ++py) {
                          uint16_t* HWY_RESTRICT dst = row;
                          for (int b = 0; b < blocksX; ++b) {
                            const uint16_t* HWY_RESTRICT m = mean[b] + py * kBlockSize;
                            const int cols = std::min(kBlockSize, w - b * kBlockSize);
                            for (int p = 0; p < cols; ++p, dst += 3) {
                              dst[0] = m[p];
                              dst[1] = m[kBlockPixels + p];
                              dst[2] = m[2 * kBlockPixels + p];
                            }
                          }
                          std::copy_n(row, 3 * w,
                                      rgb + size_t(y0 + by + py) * stride + size_t(x0) * 3);
                        }
                      });
}

// The same means blended (optionally) and through the table into a rectangle of an image.
void ResolveSampleTileTo(const uint16_t* color, const int32_t* sums, int tileX, int tileY,
                         int samples, const GammaTable& gamma, const ImageTarget& t) {
  using namespace raster;
  const int w = std::min(kTileSize, t.width - tileX * kTileSize);
  const int h = std::min(kTileSize, t.height - tileY * kTileSize);
  const int x0 = t.x + tileX * kTileSize, y0 = t.y + tileY * kTileSize;  // in the image
  uint8_t* const rgb = t.image->rgb.data();
  const size_t width = size_t(t.image->width);
  const uint8_t* HWY_RESTRICT table = gamma.table.data();
  alignas(64) uint8_t row[3 * kTileSize];
  ForEachMeanBlockRow(
      color, sums, w, h, samples,
      [&](int by, int rows, int blocksX, const uint16_t(*mean)[kColorPerBlock]) {
        for (int py = 0; py < rows; ++py) {
          const size_t first = size_t(y0 + by + py) * width + size_t(x0);  // the row's 1st pixel
          uint8_t* HWY_RESTRICT dst = row;
          for (int b = 0; b < blocksX; ++b) {
            const uint16_t* HWY_RESTRICT m = mean[b] + py * kBlockSize;
            const int cols = std::min(kBlockSize, w - b * kBlockSize);
            if (!t.alpha) {
              StoreBlockRow(dst, m, cols, table);
              dst += 3 * cols;
              continue;
            }
            for (int p = 0; p < cols; ++p, dst += 3) {
              const size_t i = first + size_t(b * kBlockSize + p);
              const float a = t.alpha[i], o = t.beta[i] * 65535.0f;
              for (int c = 0; c < 3; ++c) {
                const float v = float(m[c * kBlockPixels + p]) * a + o;
                dst[c] = table[uint16_t(std::clamp(std::nearbyint(v), 0.0f, 65535.0f))];
              }
            }
          }
          // Plainly: a cell's rows are short and start anywhere (non-temporal stores of partial
          // lines cost more than the reads they save).
          std::copy_n(row, 3 * w, rgb + first * 3);
        }
      });
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::output
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sv::output {
HWY_EXPORT(ResolveSampleTile);
HWY_EXPORT(ResolveSampleTileLinear);

void resolveSampleTile(const uint16_t* color, const int32_t* sums, int tileX, int tileY,
                       int samples, const GammaTable& gamma, Image& image) {
  SV_CHECK(samples > 1 && isSampleCount(samples));
  HWY_DYNAMIC_DISPATCH(ResolveSampleTile)(color, sums, tileX, tileY, samples, gamma, image);
}

void resolveSampleTileLinear(const uint16_t* color, const int32_t* sums, int tileX, int tileY,
                             int samples, const LinearTarget& target) {
  SV_CHECK(isSampleCount(samples));
  HWY_DYNAMIC_DISPATCH(ResolveSampleTileLinear)(color, sums, tileX, tileY, samples, target);
}

HWY_EXPORT(ResolveSampleTileTo);

void resolveSampleTileTo(const uint16_t* color, const int32_t* sums, int tileX, int tileY,
                         int samples, const GammaTable& gamma, const ImageTarget& target) {
  SV_CHECK(isSampleCount(samples) && (target.alpha == nullptr) == (target.beta == nullptr));
  HWY_DYNAMIC_DISPATCH(ResolveSampleTileTo)(color, sums, tileX, tileY, samples, gamma, target);
}
}  // namespace sv::output
#endif
