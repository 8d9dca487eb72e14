// Texture sampling for up to 16 points at once, in SIMD lanes (Highway, dispatched per call): the
// same float operations in the same order as Texture's scalar samplers (texture.cpp), so that every
// target returns their values bit for bit (tests/texture/texture_test.cpp checks each filter on every
// compiled target). Each lane has its own level of detail, so level sizes and offsets are gathered
// per lane; texels (4 × 16 bits) are gathered as two 32-bit words.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "texture/sample_block.cpp"
#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"

#include <algorithm>
#include <cmath>

#include "texture/texture.h"

HWY_BEFORE_NAMESPACE();
namespace sv::texture {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using DF = hn::CappedTag<float, 16>;
using DI = hn::RebindToSigned<DF>;
using VF = hn::Vec<DF>;
using VI = hn::Vec<DI>;

struct Lanes4 {
  VF r, g, b, a;
};

// Per-lane level geometry, and the texture's wrap modes.
struct LevelLanes {
  VI width, height, offset;
};

class BlockSampler {
 public:
  explicit BlockSampler(const Texture& t) : t_(t) {
    for (int k = 0; k < t.levelCount(); ++k) {
      widths_[k] = t.level(k).width;
      heights_[k] = t.level(k).height;
      offsets_[k] = t.offset(k);
    }
    words_ = reinterpret_cast<const int32_t*>(t.texels());
  }

  LevelLanes level(VI k) const {
    const DI di;
    return {hn::GatherIndex(di, widths_, k), hn::GatherIndex(di, heights_, k),
            hn::GatherIndex(di, offsets_, k)};
  }

  // i mod n (texture.cpp's wrapIndex) per lane.
  static VI wrap(VI i, VI n, Wrap mode) {
    const DI di;
    const DF df;
    if (mode == Wrap::clamp) return hn::Min(hn::Max(i, hn::Zero(di)), hn::Sub(n, hn::Set(di, 1)));
    const VI period = mode == Wrap::mirror ? hn::Add(n, n) : n;
    // The float quotient may be one off (|i| ≤ 2^24 + 1 is not always exact in float); the
    // integer remainder is then corrected into [0, period).
    const VI q = hn::ConvertTo(di, hn::Floor(hn::Div(hn::ConvertTo(df, i), hn::ConvertTo(df, period))));
    VI m = hn::Sub(i, hn::Mul(q, period));
    m = hn::Add(m, hn::IfThenElseZero(hn::Lt(m, hn::Zero(di)), period));
    m = hn::Sub(m, hn::IfThenElseZero(hn::Gt(m, hn::Sub(period, hn::Set(di, 1))), period));
    if (mode == Wrap::repeat) return m;
    return hn::IfThenElse(hn::Lt(m, n), m, hn::Sub(hn::Sub(period, hn::Set(di, 1)), m));
  }

  // The texels at integer (x, y) of each lane's level, as floats 0…1 (texture.cpp's toColor).
  Lanes4 texel(const LevelLanes& l, VI x, VI y) const {
    const DI di;
    const DF df;
    const VI index = hn::Add(l.offset, hn::Add(hn::Mul(wrap(y, l.height, t_.wrapY()), l.width),
                                               wrap(x, l.width, t_.wrapX())));
    const VI word = hn::Add(index, index);
    const VI rg = hn::GatherIndex(di, words_, word);
    const VI ba = hn::GatherIndex(di, words_, hn::Add(word, hn::Set(di, 1)));
    const VI low = hn::Set(di, 0xFFFF);
    const VF scale = hn::Set(df, 1.0f / 65535.0f);
    auto channel = [&](VI v) { return hn::Mul(hn::ConvertTo(df, v), scale); };
    const hn::RebindToUnsigned<DI> du;
    auto high = [&](VI v) { return hn::BitCast(di, hn::ShiftRight<16>(hn::BitCast(du, v))); };
    return {channel(hn::And(rg, low)), channel(high(rg)), channel(hn::And(ba, low)),
            channel(high(ba))};
  }

  static Lanes4 mix(const Lanes4& a, VF wa, const Lanes4& b, VF wb) {
    return {hn::Add(hn::Mul(a.r, wa), hn::Mul(b.r, wb)), hn::Add(hn::Mul(a.g, wa), hn::Mul(b.g, wb)),
            hn::Add(hn::Mul(a.b, wa), hn::Mul(b.b, wb)), hn::Add(hn::Mul(a.a, wa), hn::Mul(b.a, wb))};
  }
  static Lanes4 mix3(const Lanes4& a, VF wa, const Lanes4& b, VF wb, const Lanes4& c, VF wc) {
    auto one = [&](VF x, VF y, VF z) {
      return hn::Add(hn::Add(hn::Mul(x, wa), hn::Mul(y, wb)), hn::Mul(z, wc));
    };
    return {one(a.r, b.r, c.r), one(a.g, b.g, c.g), one(a.b, b.b, c.b), one(a.a, b.a, c.a)};
  }
  static Lanes4 select(hn::Mask<DF> m, const Lanes4& a, const Lanes4& b) {  // m ? a : b
    return {hn::IfThenElse(m, a.r, b.r), hn::IfThenElse(m, a.g, b.g), hn::IfThenElse(m, a.b, b.b),
            hn::IfThenElse(m, a.a, b.a)};
  }

  static VF sane(VF x) {
    const DF df;
    return hn::IfThenElseZero(hn::Le(hn::Abs(x), hn::Set(df, kMaxTexelCoordinate)), x);
  }

  // One level per lane (k), at that level's coordinates (x, y).
  Lanes4 sampleLevel(Filter filter, VI k, VF x, VF y) const {
    const DF df;
    const DI di;
    const LevelLanes l = level(k);
    x = sane(x);
    y = sane(y);
    if (filter == Filter::nearest) {
      const VF half = hn::Set(df, 0.5f);
      return texel(l, hn::ConvertTo(di, hn::Floor(hn::Add(x, half))),
                   hn::ConvertTo(di, hn::Floor(hn::Add(y, half))));
    }
    const VF fx = hn::Floor(x), fy = hn::Floor(y);
    const VI x0 = hn::ConvertTo(di, fx), y0 = hn::ConvertTo(di, fy);
    const VI x1 = hn::Add(x0, hn::Set(di, 1)), y1 = hn::Add(y0, hn::Set(di, 1));
    const VF g = hn::Sub(x, fx), t = hn::Sub(y, fy), one = hn::Set(df, 1.0f);
    const Lanes4 r1 = texel(l, x0, y0), r3 = texel(l, x1, y1);
    if (filter == Filter::threePoint || filter == Filter::trilinearThreePoint) {
      // Three texels per lane, as the seed intends: R4 above the diagonal, R2 below it — one
      // gather chooses per lane. The weights are texture.cpp's for the lane's triangle.
      const auto upper = hn::Ge(t, g);
      const auto upperI = hn::RebindMask(di, upper);
      const Lanes4 r24 = texel(l, hn::IfThenElse(upperI, x0, x1), hn::IfThenElse(upperI, y1, y0));
      return mix3(r3, hn::IfThenElse(upper, g, t), r24,
                  hn::IfThenElse(upper, hn::Sub(t, g), hn::Sub(g, t)), r1,
                  hn::IfThenElse(upper, hn::Sub(one, t), hn::Sub(one, g)));
    }
    const Lanes4 r2 = texel(l, x1, y0), r4 = texel(l, x0, y1);
    const VF t1 = hn::Sub(one, t);
    return mix(mix(r3, t, r2, t1), g, mix(r4, t, r1, t1), hn::Sub(one, g));
  }

  Lanes4 sample(Filter filter, VF lod, VF x0, VF y0) const {
    const DF df;
    const DI di;
    const int last = t_.levelCount() - 1;
    // lod clamped to [0, last]; NaN → 0 (as texture.cpp).
    lod = hn::Min(hn::Max(lod, hn::Zero(df)), hn::Set(df, float(last)));
    lod = hn::IfThenElseZero(hn::Ge(lod, hn::Zero(df)), lod);
    x0 = sane(x0);
    y0 = sane(y0);
    const bool trilinear = filter == Filter::trilinear || filter == Filter::trilinearThreePoint;
    const VI k = trilinear ? hn::Min(hn::ConvertTo(di, lod), hn::Set(di, last))
                           : hn::Min(hn::ConvertTo(di, hn::Add(lod, hn::Set(df, 0.5f))),
                                     hn::Set(di, last));
    // 2^-k exactly: the float with exponent 127 − k.
    const VF scale = hn::BitCast(df, hn::ShiftLeft<23>(hn::Sub(hn::Set(di, 127), k)));
    const VF x = hn::Mul(x0, scale), y = hn::Mul(y0, scale);
    const Lanes4 a = sampleLevel(filter, k, x, y);
    if (!trilinear) return a;
    const VF t = hn::Sub(lod, hn::ConvertTo(df, k));
    const VI k1 = hn::Min(hn::Add(k, hn::Set(di, 1)), hn::Set(di, last));
    const VF half = hn::Set(df, 0.5f);
    const Lanes4 b = sampleLevel(filter, k1, hn::Mul(x, half), hn::Mul(y, half));
    const auto single =
        hn::Or(hn::Eq(t, hn::Zero(df)), hn::RebindMask(df, hn::Eq(k, hn::Set(di, last))));
    return select(single, a, mix(a, hn::Sub(hn::Set(df, 1.0f), t), b, t));
  }

 private:
  const Texture& t_;
  alignas(64) int32_t widths_[32] = {}, heights_[32] = {}, offsets_[32] = {};
  const int32_t* words_;
};

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
}  // namespace sv::texture
#endif
