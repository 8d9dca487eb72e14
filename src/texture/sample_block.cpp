// sampleBlock and anisotropicBlock (texture.h): the block sampler of sample_block-inl.h, one
// dispatched call per block of up to 16 points.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "texture/sample_block.cpp"
#include <algorithm>
#include <cmath>

#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"
#include "texture/sample_block-inl.h"
#include "texture/texture.h"

HWY_BEFORE_NAMESPACE();
namespace sv::texture {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

void SampleBlock(const Texture& texture, Filter filter, const float* lod, const float* x0,
                 const float* y0, int count, float out[4][16]) {
  const DF df;
  const size_t n = hn::Lanes(df);
  const BlockSampler sampler(texture);
  alignas(64) float in[3][16] = {};
  std::copy_n(lod, count, in[0]);
  std::copy_n(x0, count, in[1]);
  std::copy_n(y0, count, in[2]);
  for (size_t i = 0; i < size_t(count); i += n) {
    const Lanes4 c = sampler.sample(filter, hn::Load(df, in[0] + i), hn::Load(df, in[1] + i),
                                    hn::Load(df, in[2] + i));
    alignas(64) float tmp[4][16];
    hn::Store(c.r, df, tmp[0]);
    hn::Store(c.g, df, tmp[1]);
    hn::Store(c.b, df, tmp[2]);
    hn::Store(c.a, df, tmp[3]);
    const size_t m = std::min(n, size_t(count) - i);
    for (int ch = 0; ch < 4; ++ch) std::copy_n(tmp[ch], m, out[ch] + i);
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::texture
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sv::texture {
HWY_EXPORT(SampleBlock);

void sampleBlock(const Texture& texture, Filter filter, const float* lod, const float* x0,
                 const float* y0, int count, float out[4][16]) {
  HWY_DYNAMIC_DISPATCH(SampleBlock)(texture, filter, lod, x0, y0, std::clamp(count, 0, 16), out);
}

void anisotropicBlock(const Texture& texture, const Footprint* footprints, const float* x0,
                      const float* y0, int count, float out[4][16]) {
  count = std::clamp(count, 0, 16);
  // The probes in pixel order, 16 to a chunk; a pixel's probes may straddle two chunks, and its
  // sum adds them in probe order either way (as Texture::anisotropic does).
  alignas(64) float lod[16] = {}, x[16] = {}, y[16] = {}, probe[4][16];
  int owner[16], filled = 0;
  float sum[4][16] = {}, weight[16];
  auto flush = [&] {
    HWY_DYNAMIC_DISPATCH(SampleBlock)(texture, Filter::trilinear, lod, x, y, filled, probe);
    for (int j = 0; j < filled; ++j)
      for (int ch = 0; ch < 4; ++ch) sum[ch][owner[j]] += probe[ch][j];
    filled = 0;
  };
  for (int i = 0; i < count; ++i) {
    float pixelLod, px[Texture::kMaxProbes], py[Texture::kMaxProbes];
    const int n = anisotropicProbes(footprints[i], x0[i], y0[i], pixelLod, px, py);
    weight[i] = 1.0f / float(n);
    for (int k = 0; k < n; ++k) {
      lod[filled] = pixelLod;
      x[filled] = px[k];
      y[filled] = py[k];
      owner[filled++] = i;
      if (filled == 16) flush();
    }
  }
  if (filled) flush();
  for (int ch = 0; ch < 4; ++ch)
    for (int i = 0; i < 16; ++i) out[ch][i] = i < count ? sum[ch][i] * weight[i] : 0.0f;
  // As Texture::anisotropic: an opaque texture's alpha is exactly 1.
  if (texture.opaque()) std::fill_n(out[3], count, 1.0f);
}
}  // namespace sv::texture
#endif
