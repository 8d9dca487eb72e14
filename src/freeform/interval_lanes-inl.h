// Interval arithmetic in SIMD lanes (Highway, per target) for the free-form kernels
// (slab_bounds.cpp, window_rays.cpp, surface_points.cpp): an Interval per lane, with quadric.h's
// operators and freeform.cpp's perturbation term and widening, each in the scalar code's order of
// operations — the build contracts nothing into FMAs — so that a lane computes the scalar
// function's bits on every target.
//
// Per-target include guard (Highway's convention for -inl.h files).
#if defined(SV_FREEFORM_INTERVAL_LANES_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef SV_FREEFORM_INTERVAL_LANES_INL_H_
#undef SV_FREEFORM_INTERVAL_LANES_INL_H_
#else
#define SV_FREEFORM_INTERVAL_LANES_INL_H_
#endif

#include "hwy/highway.h"

HWY_BEFORE_NAMESPACE();
namespace sv::freeform {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using DD = hn::CappedTag<double, 16>;  // 8 lanes on AVX-512, 4 on AVX2, 2 on SSE
using VD = hn::Vec<DD>;
using MD = hn::Mask<DD>;

struct Lanes {  // an Interval per lane
  VD lo, hi;
};

// a·s, the sign of s deciding which end is which.
HWY_INLINE Lanes Scale(DD d, const Lanes& a, double s) {
  const VD v = hn::Set(d, s);
  return s >= 0 ? Lanes{hn::Mul(a.lo, v), hn::Mul(a.hi, v)}
                : Lanes{hn::Mul(a.hi, v), hn::Mul(a.lo, v)};
}
HWY_INLINE Lanes Sum(const Lanes& a, const Lanes& b) {
  return {hn::Add(a.lo, b.lo), hn::Add(a.hi, b.hi)};
}
HWY_INLINE Lanes Product(const Lanes& a, const Lanes& b) {
  const VD p0 = hn::Mul(a.lo, b.lo), p1 = hn::Mul(a.lo, b.hi);
  const VD p2 = hn::Mul(a.hi, b.lo), p3 = hn::Mul(a.hi, b.hi);
  return {hn::Min(hn::Min(p0, p1), hn::Min(p2, p3)), hn::Max(hn::Max(p0, p1), hn::Max(p2, p3))};
}
HWY_INLINE MD ContainsZero(DD d, const Lanes& a) {
  return hn::And(hn::Le(a.lo, hn::Zero(d)), hn::Ge(a.hi, hn::Zero(d)));
}
// freeform.cpp's widened: a margin for the rounding of the arithmetic.
HWY_INLINE Lanes Widened(DD d, const Lanes& h) {
  const VD margin = hn::Add(hn::Mul(hn::Set(d, 1e-12), hn::Add(hn::Abs(h.lo), hn::Abs(h.hi))),
                            hn::Set(d, 1e-300));
  return {hn::Sub(h.lo, margin), hn::Add(h.hi, margin)};
}

// freeform.cpp's addPerturbation: a perturbation bounded by v (slope dv) of weight w adds
// w·max(0, v)³·u⁻⁴ to `value` and w·(3p²·p'·u⁻⁴ − 4p³·u'·u⁻⁵) to `slope` (u' = u1).
HWY_INLINE void AddPerturbation(DD d, const Lanes& v, const Lanes& dv, double w, const Lanes& u4,
                                const Lanes& u5, double u1, Lanes& value, Lanes& slope) {
  const VD zero = hn::Zero(d);
  const Lanes p{hn::Max(v.lo, zero), hn::Max(v.hi, zero)};
  const MD positive = hn::Gt(p.hi, zero);
  const Lanes dp{hn::IfThenElseZero(positive, dv.lo), hn::IfThenElseZero(positive, dv.hi)};
  const Lanes cube{hn::Mul(hn::Mul(p.lo, p.lo), p.lo), hn::Mul(hn::Mul(p.hi, p.hi), p.hi)};
  const Lanes square{hn::Mul(p.lo, p.lo), hn::Mul(p.hi, p.hi)};  // exact: p ≥ 0
  value = Sum(value, Scale(d, Product(cube, u4), w));
  slope = Sum(slope, Scale(d,
                           Sum(Scale(d, Product(Product(square, dp), u4), 3),
                               Scale(d, Product(cube, u5), -4 * u1)),
                           w));
}

// freeform.cpp's takeMinimum: min(F', C) for a clip bounded by `clip` (slope `clipSlope`) — its
// slope where it is the minimum throughout, both slopes where either may be.
HWY_INLINE void TakeMinimum(const Lanes& clip, const Lanes& clipSlope, Lanes& value, Lanes& slope) {
  const MD below = hn::Lt(clip.hi, value.lo);
  const MD overlap = hn::AndNot(below, hn::Le(clip.lo, value.hi));
  slope = {hn::IfThenElse(below, clipSlope.lo,
                          hn::IfThenElse(overlap, hn::Min(slope.lo, clipSlope.lo), slope.lo)),
           hn::IfThenElse(below, clipSlope.hi,
                          hn::IfThenElse(overlap, hn::Max(slope.hi, clipSlope.hi), slope.hi))};
  value = {hn::Min(value.lo, clip.lo), hn::Min(value.hi, clip.hi)};
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::freeform
HWY_AFTER_NAMESPACE();

#endif  // per-target include guard
