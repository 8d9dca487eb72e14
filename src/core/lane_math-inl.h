// Logarithm and power of two in SIMD lanes (Highway, per target) with Add, Mul, Div and bit
// operations only — no fused multiply-add, no library call — so that every target, the scalar
// fallback included, gives the same bits: the terrain's texture levels of detail
// (terrain/shade_lanes.cpp) and the volume's step opacities (volume/sample_kernel.cpp).
//
// Per-target include guard (Highway's convention for -inl.h files): included once per SIMD target
// by the files that use it, so that it inlines into their kernels.
#if defined(SV_CORE_LANE_MATH_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef SV_CORE_LANE_MATH_INL_H_
#undef SV_CORE_LANE_MATH_INL_H_
#else
#define SV_CORE_LANE_MATH_INL_H_
#endif

#include "hwy/highway.h"

HWY_BEFORE_NAMESPACE();
namespace sv::core {
namespace HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;

// log2 x for a positive, normal, finite x: the exponent plus log2 of the mantissa m ∈ [1, 2) by
// the series of atanh: log2 m = 2/ln 2 · (t + t³/3 + t⁵/5 + t⁷/7), t = (m − 1)/(m + 1) ≤ 1/3 —
// within 2·10⁻⁵.
template <class DF>
HWY_INLINE hn::Vec<DF> Log2Positive(DF df, hn::Vec<DF> x) {
  const hn::RebindToSigned<DF> di;
  using VF = hn::Vec<DF>;
  const auto bits = hn::BitCast(di, x);
  const VF exponent = hn::ConvertTo(df, hn::Sub(hn::ShiftRight<23>(bits), hn::Set(di, 127)));
  const VF m =
      hn::BitCast(df, hn::Or(hn::And(bits, hn::Set(di, 0x7FFFFF)), hn::Set(di, 0x3F800000)));
  const VF one = hn::Set(df, 1.0f);
  const VF t = hn::Div(hn::Sub(m, one), hn::Add(m, one)), t2 = hn::Mul(t, t);
  VF series = hn::Set(df, 1.0f / 7);
  series = hn::Add(hn::Mul(series, t2), hn::Set(df, 1.0f / 5));
  series = hn::Add(hn::Mul(series, t2), hn::Set(df, 1.0f / 3));
  series = hn::Add(hn::Mul(series, t2), one);
  return hn::Add(exponent, hn::Mul(hn::Mul(series, t), hn::Set(df, 2.8853900817779268f)));
}

// 2^y, y clamped to [−126, 126]: 2^⌊y⌋ from the exponent's bits times 2^f, f = y − ⌊y⌋ ∈ [0, 1),
// by the Taylor series of e^(f·ln 2) to the seventh power — within 10⁻⁷ relative.
template <class DF>
HWY_INLINE hn::Vec<DF> Exp2(DF df, hn::Vec<DF> y) {
  const hn::RebindToSigned<DF> di;
  using VF = hn::Vec<DF>;
  y = hn::Min(hn::Max(y, hn::Set(df, -126.0f)), hn::Set(df, 126.0f));
  const VF whole = hn::Floor(y);
  const VF u = hn::Mul(hn::Sub(y, whole), hn::Set(df, 0.6931471805599453f));
  VF p = hn::Set(df, 1.0f / 5040);
  for (const float c : {1.0f / 720, 1.0f / 120, 1.0f / 24, 1.0f / 6, 0.5f, 1.0f, 1.0f})
    p = hn::Add(hn::Mul(p, u), hn::Set(df, c));
  const VF scale =
      hn::BitCast(df, hn::ShiftLeft<23>(hn::Add(hn::ConvertTo(di, whole), hn::Set(di, 127))));
  return hn::Mul(p, scale);
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::core
HWY_AFTER_NAMESPACE();

#endif  // SV_CORE_LANE_MATH_INL_H_
