// Based on: SPEC §13 (a light point's splat added in linear light), §5 (the frame's samples).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "lights/splat_blocks.cpp"
#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"
#include "lights/splat_blocks.h"
#include "raster/framebuffer.h"

HWY_BEFORE_NAMESPACE();
namespace sv::lights {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

void AddSplat(uint16_t* HWY_RESTRICT tileColor, int samples, const SplatInTile& s) {
  using namespace raster;
  const hn::CappedTag<float, kBlockPixels> df;
  const hn::Rebind<int32_t, decltype(df)> di;
  const hn::Rebind<uint16_t, decltype(df)> d16;
  const size_t lanes = hn::Lanes(df);
  const auto half = hn::Set(df, 0.5f);
  const decltype(hn::Zero(df)) rgb[3] = {hn::Set(df, s.rgb[0]), hn::Set(df, s.rgb[1]),
                                         hn::Set(df, s.rgb[2])};
  for (int by = s.y0 & ~(kBlockSize - 1); by <= s.y1; by += kBlockSize)
    for (int bx = s.x0 & ~(kBlockSize - 1); bx <= s.x1; bx += kBlockSize) {
      // The block's weights, 0 outside the splat's part of the tile (a 0 adds nothing: ⌊½⌋).
      float rowW[kBlockSize], colW[kBlockSize];
      for (int i = 0; i < kBlockSize; ++i) {
        const int y = by + i, x = bx + i;
        rowW[i] = y >= s.y0 && y <= s.y1 ? s.ky[y - s.kernelY] : 0.0f;
        colW[i] = x >= s.x0 && x <= s.x1 ? s.kx[x - s.kernelX] : 0.0f;
      }
      alignas(64) float w[kBlockPixels];
      for (int p = 0; p < kBlockPixels; ++p) w[p] = colW[p & (kBlockSize - 1)] * rowW[p >> kBlockLog2];
      uint16_t* block = tileColor + tileBlock(bx, by) * size_t(samples) * kColorPerBlock;
      for (size_t p = 0; p < size_t(kBlockPixels); p += lanes) {
        const auto wv = hn::Load(df, w + p);
        for (int ch = 0; ch < kColorChannels; ++ch) {
          // Rounded to the nearest 16-bit step (non-negative: + ½ and truncate), saturating.
          const auto add =
              hn::DemoteTo(d16, hn::ConvertTo(di, hn::Add(hn::Mul(rgb[ch], wv), half)));
          uint16_t* c = block + ch * kBlockPixels + p;
          for (int k = 0; k < samples; ++k, c += kColorPerBlock)
            hn::StoreU(hn::SaturatedAdd(hn::LoadU(d16, c), add), d16, c);
        }
      }
    }
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::lights
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sv::lights {
HWY_EXPORT(AddSplat);

void addSplat(uint16_t* tileColor, int samples, const SplatInTile& s) {
  HWY_DYNAMIC_DISPATCH(AddSplat)(tileColor, samples, s);
}
}  // namespace sv::lights
#endif
