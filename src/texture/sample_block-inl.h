// The SIMD block sampler (Highway, per target): the same float operations in the same order as
// Texture's scalar samplers (texture.cpp), so that every target returns their values bit for bit
// (tests/texture/texture_test.cpp checks each filter on every compiled target). Included by
// sample_block.cpp (sampleBlock, one call per block) and by the shading stage, which samples inside
// its own SIMD loop without a dispatch or a copy of its inputs. Each lane has its own level of
// detail, so level sizes and offsets are gathered per lane. Texels are 32-bit words (texture.h,
// PackedTexel); a bilinear cell's two texels in a row are one 64-bit word — rows carry a copy of
// their wrapped neighbour at column `width` — and are gathered as such, half the gathers of
// fetching each texel. The shading stage also requests a block's texel lines here (prefetch) a
// queue of blocks before it samples them.
//
// Per-target include guard (Highway's convention for -inl.h files).
#if defined(SV_TEXTURE_SAMPLE_BLOCK_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef SV_TEXTURE_SAMPLE_BLOCK_INL_H_
#undef SV_TEXTURE_SAMPLE_BLOCK_INL_H_
#else
#define SV_TEXTURE_SAMPLE_BLOCK_INL_H_
#endif

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include "hwy/highway.h"
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

// Per-lane level geometry.
struct LevelLanes {
  VI width, height, offset;
};

class BlockSampler {
 public:
  explicit BlockSampler(const Texture& t)
      : t_(t),
        table_(t.levelTable()),
        pow2_(t.powerOfTwo()),
        opaque_(t.opaque()),
        pairs_(reinterpret_cast<const int64_t*>(t.texels())),
        words_(reinterpret_cast<const int32_t*>(t.texels())) {}

  LevelLanes level(VI k) const {
    const DI di;
    if constexpr (!HWY_HAVE_SCALABLE && hn::MaxLanes(DI()) >= size_t(Texture::kMaxLevels)) {
      // A whole table is one vector: three permutes by k, whether the lanes share a level or
      // not. Lanes of a batch that mixes triangles often differ in level, and the three 16-lane
      // gathers below took a sixth of the sampler's time (docs/performance.md, "Pixel shading and
      // texture").
      const auto index = hn::IndicesFromVec(di, k);
      return {hn::TableLookupLanes(hn::Load(di, table_.width), index),
              hn::TableLookupLanes(hn::Load(di, table_.height), index),
              hn::TableLookupLanes(hn::Load(di, table_.offset), index)};
    }
    // Neighbouring pixels mostly share a level: then three broadcasts instead of three gathers.
    const int32_t k0 = hn::GetLane(k);
    if (hn::AllTrue(di, hn::Eq(k, hn::Set(di, k0))))
      return {hn::Set(di, table_.width[k0]), hn::Set(di, table_.height[k0]),
              hn::Set(di, table_.offset[k0])};
    return {hn::GatherIndex(di, table_.width, k), hn::GatherIndex(di, table_.height, k),
            hn::GatherIndex(di, table_.offset, k)};
  }

  // i mod n (texture.cpp's wrapIndex) per lane; for power-of-two sizes a mask (the same values).
  VI wrap(VI i, VI n, Wrap mode) const {
    const DI di;
    const DF df;
    const VI one = hn::Set(di, 1);
    if (mode == Wrap::clamp) return hn::Min(hn::Max(i, hn::Zero(di)), hn::Sub(n, one));
    const VI period = mode == Wrap::mirror ? hn::Add(n, n) : n;
    VI m;
    if (pow2_) {
      m = hn::And(i, hn::Sub(period, one));  // two's complement: also right for i < 0
    } else {
      // The float quotient may be one off (|i| ≤ 2^24 + 1 is not always exact in float); the
      // integer remainder is then corrected into [0, period).
      const VI q =
          hn::ConvertTo(di, hn::Floor(hn::Div(hn::ConvertTo(df, i), hn::ConvertTo(df, period))));
      m = hn::Sub(i, hn::Mul(q, period));
      m = hn::Add(m, hn::IfThenElseZero(hn::Lt(m, hn::Zero(di)), period));
      m = hn::Sub(m, hn::IfThenElseZero(hn::Gt(m, hn::Sub(period, one)), period));
    }
    if (mode == Wrap::repeat) return m;
    return hn::IfThenElse(hn::Lt(m, n), m, hn::Sub(hn::Sub(period, one), m));
  }

  // Packed texels as floats 0…1: texture.cpp's unpackTexel, the same two steps per channel; alpha
  // 1 without reading it for an opaque texture (kOpaque, Texture::opaque).
  template <bool kOpaque>
  static Lanes4 unpack(VI t) {
    const DI di;
    const DF df;
    const hn::RebindToUnsigned<DI> du;
    const VI byte = hn::Set(di, 0xFF);
    const VF colourScale = hn::Set(df, 1.0f / 65025.0f);
    auto colour = [&](VI c) {
      c = hn::And(c, byte);
      return hn::Mul(hn::ConvertTo(df, hn::Mul(c, c)), colourScale);
    };
    VF a = hn::Set(df, 1.0f);
    if constexpr (!kOpaque)
      a = hn::Mul(hn::ConvertTo(df, hn::BitCast(di, hn::ShiftRight<24>(hn::BitCast(du, t)))),
                  hn::Set(df, 1.0f / 255.0f));
    return {colour(t), colour(hn::ShiftRight<8>(t)), colour(hn::ShiftRight<16>(t)), a};
  }

  // The texel at `index` (into Texture::texels()) of every lane.
  VI fetch(VI index) const { return hn::GatherIndex(DI(), words_, index); }

  // The texels at `index` and index + 1 of every lane: one 64-bit gather per two texels.
  void fetchPair(VI index, VI& left, VI& right) const {
    const DI di;
#if HWY_TARGET == HWY_SCALAR
    left = fetch(index);
    right = fetch(hn::Add(index, hn::Set(di, 1)));
#else
    const hn::Half<DI> dh;
    const hn::Rebind<int64_t, decltype(dh)> d64;
    // Byte offsets: a pair starts at any texel, so 4-byte aligned.
    auto offsets = [&](auto half) { return hn::ShiftLeft<2>(hn::PromoteTo(d64, half)); };
    const auto lo =
        hn::BitCast(di, hn::GatherOffset(d64, pairs_, offsets(hn::LowerHalf(dh, index))));
    const auto hi =
        hn::BitCast(di, hn::GatherOffset(d64, pairs_, offsets(hn::UpperHalf(dh, index))));
    left = hn::ConcatEven(di, hi, lo);  // little-endian: the lower word is the texel at index
    right = hn::ConcatOdd(di, hi, lo);
#endif
  }

  // Blends; for an opaque texture alpha stays a's (1), unblended.
  template <bool kOpaque>
  static Lanes4 mix(const Lanes4& a, VF wa, const Lanes4& b, VF wb) {
    return {hn::Add(hn::Mul(a.r, wa), hn::Mul(b.r, wb)),
            hn::Add(hn::Mul(a.g, wa), hn::Mul(b.g, wb)),
            hn::Add(hn::Mul(a.b, wa), hn::Mul(b.b, wb)),
            kOpaque ? a.a : hn::Add(hn::Mul(a.a, wa), hn::Mul(b.a, wb))};
  }
  template <bool kOpaque>
  static Lanes4 mix3(const Lanes4& a, VF wa, const Lanes4& b, VF wb, const Lanes4& c, VF wc) {
    auto one = [&](VF x, VF y, VF z) {
      return hn::Add(hn::Add(hn::Mul(x, wa), hn::Mul(y, wb)), hn::Mul(z, wc));
    };
    return {one(a.r, b.r, c.r), one(a.g, b.g, c.g), one(a.b, b.b, c.b),
            kOpaque ? a.a : one(a.a, b.a, c.a)};
  }
  static Lanes4 select(hn::Mask<DF> m, const Lanes4& a, const Lanes4& b) {  // m ? a : b
    return {hn::IfThenElse(m, a.r, b.r), hn::IfThenElse(m, a.g, b.g), hn::IfThenElse(m, a.b, b.b),
            hn::IfThenElse(m, a.a, b.a)};
  }

  static VF sane(VF x) {
    const DF df;
    return hn::IfThenElseZero(hn::Le(hn::Abs(x), hn::Set(df, kMaxTexelCoordinate)), x);
  }

  // One level per lane (k), at that level's coordinates (x, y). Each coordinate is wrapped once
  // and each row's start computed once, whatever the number of texels read.
  template <bool kOpaque>
  Lanes4 sampleLevel(Filter filter, VI k, VF x, VF y) const {
    const DF df;
    const DI di;
    const LevelLanes l = level(k);
    x = sane(x);
    y = sane(y);
    const Wrap wx = t_.wrapX(), wy = t_.wrapY();
    const VI one = hn::Set(di, 1);
    const VI stride = hn::Add(l.width, one);  // rows of width + 1 (texture.h, LevelView)
    auto row = [&](VI yi) { return hn::Add(l.offset, hn::Mul(wrap(yi, l.height, wy), stride)); };
    if (filter == Filter::nearest) {
      const VF half = hn::Set(df, 0.5f);
      return unpack<kOpaque>(
          fetch(hn::Add(row(hn::ConvertTo(di, hn::Floor(hn::Add(y, half)))),
                        wrap(hn::ConvertTo(di, hn::Floor(hn::Add(x, half))), l.width, wx))));
    }
    const VF fx = hn::Floor(x), fy = hn::Floor(y);
    const VI xi = hn::ConvertTo(di, fx), yi = hn::ConvertTo(di, fy);
    const VI x0 = wrap(xi, l.width, wx), x1 = wrap(hn::Add(xi, one), l.width, wx);
    const VI row0 = row(yi), row1 = row(hn::Add(yi, one));
    // The cell's texels: t1 (x0, y0), t2 (x1, y0), t3 (x1, y1), t4 (x0, y1) — R1…R4 of SPEC §7.
    // Column x0 + 1 holds x1 unless the wrap turned back (mirror, or clamp left of the image):
    // column `width` holds the texel that wraps there (the border copy).
    VI t1, t2, t3, t4;
    const VI next = hn::Add(x0, one);
    const VI border = wx == Wrap::repeat ? hn::Zero(di) : hn::Sub(l.width, one);
    const auto paired = hn::Eq(x1, hn::IfThenElse(hn::Eq(next, l.width), border, next));
    if (hn::AllTrue(di, paired)) {
      fetchPair(hn::Add(row0, x0), t1, t2);
      fetchPair(hn::Add(row1, x0), t4, t3);
    } else {
      t1 = fetch(hn::Add(row0, x0));
      t2 = fetch(hn::Add(row0, x1));
      t3 = fetch(hn::Add(row1, x1));
      t4 = fetch(hn::Add(row1, x0));
    }
    const VF g = hn::Sub(x, fx), t = hn::Sub(y, fy), onef = hn::Set(df, 1.0f);
    const Lanes4 r1 = unpack<kOpaque>(t1), r3 = unpack<kOpaque>(t3);
    if (filter == Filter::threePoint || filter == Filter::trilinearThreePoint) {
      // Three texels per lane, as the seed intends: R4 above the diagonal, R2 below it. The
      // weights are texture.cpp's for the lane's triangle.
      const auto upper = hn::Ge(t, g);
      const Lanes4 r24 = unpack<kOpaque>(hn::IfThenElse(hn::RebindMask(di, upper), t4, t2));
      return mix3<kOpaque>(r3, hn::IfThenElse(upper, g, t), r24,
                           hn::IfThenElse(upper, hn::Sub(t, g), hn::Sub(g, t)), r1,
                           hn::IfThenElse(upper, hn::Sub(onef, t), hn::Sub(onef, g)));
    }
    const Lanes4 r2 = unpack<kOpaque>(t2), r4 = unpack<kOpaque>(t4);
    const VF t1f = hn::Sub(onef, t);
    return mix<kOpaque>(mix<kOpaque>(r3, t, r2, t1f), g, mix<kOpaque>(r4, t, r1, t1f),
                        hn::Sub(onef, g));
  }

  // Requests the cache lines of level k (clamped to the pyramid) under the box [xMin, xMax] ×
  // [yMin, yMax] (level-0 texels; at most 32 × 32 texels of level k), so that a sampler reading
  // points inside the box there finds them arrived. For points close together — a block of
  // pixels — that is a few lines per row. With `coarser` (the trilinear filters) also level
  // k + 1's rows under the box, one line each — the line under the box's centre: that level's box
  // is half as wide and mostly within a line, and every line of it cost more to request than it
  // hid (docs/performance.md). Coordinates past kMaxTexelCoordinate request nothing.
  void prefetch(int k, bool coarser, float xMin, float xMax, float yMin, float yMax) const {
    // Also false for NaN.
    if (!(xMin <= xMax && yMin <= yMax && std::fabs(xMin) <= kMaxTexelCoordinate &&
          std::fabs(xMax) <= kMaxTexelCoordinate && std::fabs(yMin) <= kMaxTexelCoordinate &&
          std::fabs(yMax) <= kMaxTexelCoordinate))
      return;
    const int last = t_.levelCount() - 1;
    k = std::clamp(k, 0, last);
    // 2^-k exactly (k < kMaxLevels).
    const float scale = std::bit_cast<float>(uint32_t(127 - k) << 23);
    // The cells' corners run from ⌊min⌋ to ⌊max⌋ + 1.
    const int x0 = int(std::floor(xMin * scale)), y0 = int(std::floor(yMin * scale));
    requestRows(k, y0, std::min(int(std::floor(yMax * scale)) + 1, y0 + 31), x0,
                std::min(int(std::floor(xMax * scale)) + 1, x0 + 31));
    if (!coarser || k == last) return;
    const float half = 0.5f * scale;
    const int xc = int(std::floor(0.5f * (xMin + xMax) * half)), yc = int(std::floor(yMin * half));
    requestRows(k + 1, yc, std::min(int(std::floor(yMax * half)) + 1, yc + 31), xc, xc);
  }

  // Texture::sample's values (by `filter`, at level of detail lod and level-0 coordinates x0, y0),
  // bit for bit, in every lane.
  Lanes4 sample(Filter filter, VF lod, VF x0, VF y0) const {
    return opaque_ ? sampleAs<true>(filter, lod, x0, y0) : sampleAs<false>(filter, lod, x0, y0);
  }

 private:
  template <bool kOpaque>
  Lanes4 sampleAs(Filter filter, VF lod, VF x0, VF y0) const {
    const DF df;
    const DI di;
    const int last = t_.levelCount() - 1;
    // lod clamped to [0, last]; NaN → 0 (as texture.cpp).
    lod = hn::Min(hn::Max(lod, hn::Zero(df)), hn::Set(df, float(last)));
    lod = hn::IfThenElseZero(hn::Ge(lod, hn::Zero(df)), lod);
    x0 = sane(x0);
    y0 = sane(y0);
    const bool trilinear = filter == Filter::trilinear || filter == Filter::trilinearThreePoint;
    const VI k =
        trilinear ? hn::Min(hn::ConvertTo(di, lod), hn::Set(di, last))
                  : hn::Min(hn::ConvertTo(di, hn::Add(lod, hn::Set(df, 0.5f))), hn::Set(di, last));
    // 2^-k exactly: the float with exponent 127 − k.
    const VF scale = hn::BitCast(df, hn::ShiftLeft<23>(hn::Sub(hn::Set(di, 127), k)));
    const VF x = hn::Mul(x0, scale), y = hn::Mul(y0, scale);
    const Lanes4 a = sampleLevel<kOpaque>(filter, k, x, y);
    if (!trilinear) return a;
    const VF t = hn::Sub(lod, hn::ConvertTo(df, k));
    const auto single =
        hn::Or(hn::Eq(t, hn::Zero(df)), hn::RebindMask(df, hn::Eq(k, hn::Set(di, last))));
    // Magnified (lod 0) or exactly on a level everywhere: the second level is not read at all.
    if (hn::AllTrue(df, single)) return a;
    const VI k1 = hn::Min(hn::Add(k, hn::Set(di, 1)), hn::Set(di, last));
    const VF half = hn::Set(df, 0.5f);
    const Lanes4 b = sampleLevel<kOpaque>(filter, k1, hn::Mul(x, half), hn::Mul(y, half));
    return select(single, a, mix<kOpaque>(a, hn::Sub(hn::Set(df, 1.0f), t), b, t));
  }

  // A prefetch the compiler keeps: GCC counts __builtin_prefetch as having no side effect and
  // deletes a loop that does nothing else; the empty asm statement that takes the address is a use
  // it must keep.
  static void request(const void* p) {
    __builtin_prefetch(p, 0, 3);
    asm volatile("" : : "r"(p));
  }

  // Requests, in rows y0…y1 of level k (before wrapping), the lines of columns x0 and x1 (x0 ≤
  // x1 ≤ x0 + 31), and of column x0 + 16 when they lie further apart than a line. The rows' starts
  // are computed in lanes, and each row's two lines requested even when they are one (a test per
  // row would be guessed wrong half the time) — unless x0 = x1, the same column: the scalar loop
  // this replaced, with a wrap and a test per row, cost more than the requests
  // (docs/performance.md).
  void requestRows(int k, int y0, int y1, int x0, int x1) const {
    const DI di;
    const int n = int(hn::Lanes(di));
    const VI width = hn::Set(di, table_.width[k]);
    auto column = [&](int x) { return hn::GetLane(wrap(hn::Set(di, x), width, t_.wrapX())); };
    const int32_t* a = words_ + column(x0);
    const int32_t* b = words_ + column(x1);
    const bool two = x1 != x0, wide = x1 - x0 > 16;
    const int32_t* m = words_ + (wide ? column(x0 + 16) : 0);
    const VI stride = hn::Add(width, hn::Set(di, 1)), height = hn::Set(di, table_.height[k]);
    const VI offset = hn::Set(di, table_.offset[k]);
    alignas(64) static constexpr int32_t kLane[16] = {0, 1, 2,  3,  4,  5,  6,  7,
                                                      8, 9, 10, 11, 12, 13, 14, 15};
    alignas(64) int32_t start[16];
    for (int y = y0; y <= y1; y += n) {
      const VI row = wrap(hn::Add(hn::Set(di, y), hn::Load(di, kLane)), height, t_.wrapY());
      hn::Store(hn::Add(offset, hn::Mul(row, stride)), di, start);
      const int count = std::min(n, y1 - y + 1);
      for (int i = 0; i < count; ++i) {
        request(a + start[i]);
        if (two) request(b + start[i]);
        if (wide) request(m + start[i]);
      }
    }
  }

  const Texture& t_;
  const Texture::LevelTable& table_;
  const bool pow2_;
  const bool opaque_;
  const int64_t* pairs_;
  const int32_t* words_;
};

}  // namespace HWY_NAMESPACE
}  // namespace sv::texture
HWY_AFTER_NAMESPACE();

#endif  // SV_TEXTURE_SAMPLE_BLOCK_INL_H_
