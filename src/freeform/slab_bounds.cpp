// ProjectedFreeForm::slabsHolding: the bounds of one screen window's slabs in depth (the binary
// tree in depth of Caster::cell, raycast.cpp, and of FreeFormFrame::markTiles), every slab a SIMD
// lane (Highway, per target). The window's x and y are the same for all its slabs, so what depends
// on them alone — per quadric, its centre's quadratic in z and the gradient's linear terms — is
// worked out once per window instead of once per slab.
//
// Each lane performs the operations of ProjectedFreeForm::bound (freeform.cpp) and Quadric::bound
// (quadric.cpp) in the same order, and the build does not contract them into FMAs, so every target
// answers as the scalar bound does, bit for bit (tests/freeform checks each compiled target).
//
// Based on: SPEC §12 (seed 003: binary subdivision in depth, cells rejected by bounds).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "freeform/slab_bounds.cpp"
#include <algorithm>
#include <cmath>

#include "freeform/freeform.h"
#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"

HWY_BEFORE_NAMESPACE();
namespace sv::freeform {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using DD = hn::CappedTag<double, 16>;
using VD = hn::Vec<DD>;
using MD = hn::Mask<DD>;

struct Lanes {  // an Interval per lane
  VD lo, hi;
};

// The window x × y as Quadric::bound reads it: centre and half-widths.
struct Box {
  double xc, yc, rx, ry;
};

// Quadric::bound(x, y, z) for the lanes' z.
HWY_INLINE Lanes QuadricBound(DD d, const Quadric& q, const Box& box, const Lanes& z) {
  const auto& c = q.c;
  const double xc = box.xc, yc = box.yc, rx = box.rx, ry = box.ry;
  // The centre, C·z² + b·z + k, by quadraticRange.
  const double b = c[4] * xc + c[5] * yc + c[8];
  const double k = (c[0] * xc + c[3] * yc + c[6]) * xc + (c[1] * yc + c[7]) * yc + c[9];
  const VD a = hn::Set(d, c[2]), vb = hn::Set(d, b), vk = hn::Set(d, k);
  const VD fLo = hn::Add(hn::Mul(hn::Add(hn::Mul(a, z.lo), vb), z.lo), vk);
  const VD fHi = hn::Add(hn::Mul(hn::Add(hn::Mul(a, z.hi), vb), z.hi), vk);
  VD lo = hn::Min(fLo, fHi), hi = hn::Max(fLo, fHi);
  if (c[2] != 0) {
    const double vertex = -b / (2 * c[2]);
    const double fVertex = (c[2] * vertex + b) * vertex + k;
    const VD v = hn::Set(d, vertex), fv = hn::Set(d, fVertex);
    const auto within = hn::And(hn::Lt(z.lo, v), hn::Lt(v, z.hi));
    lo = hn::IfThenElse(within, hn::Min(lo, fv), lo);
    hi = hn::IfThenElse(within, hn::Max(hi, fv), hi);
  }
  // The gradient terms, largest at the ends of z.
  const double gx0 = 2 * c[0] * xc + c[3] * yc + c[6], gy0 = 2 * c[1] * yc + c[3] * xc + c[7];
  const VD e = hn::Set(d, c[4]), f = hn::Set(d, c[5]), vgx = hn::Set(d, gx0), vgy = hn::Set(d, gy0);
  const VD gx =
      hn::Max(hn::Abs(hn::Add(vgx, hn::Mul(e, z.lo))), hn::Abs(hn::Add(vgx, hn::Mul(e, z.hi))));
  const VD gy =
      hn::Max(hn::Abs(hn::Add(vgy, hn::Mul(f, z.lo))), hn::Abs(hn::Add(vgy, hn::Mul(f, z.hi))));
  const VD linear = hn::Add(hn::Mul(gx, hn::Set(d, rx)), hn::Mul(gy, hn::Set(d, ry)));
  const Interval quadratic = Interval{0, rx * rx} * c[0] + Interval{0, ry * ry} * c[1] +
                             Interval{-1, 1} * (std::fabs(c[3]) * rx * ry);
  return {hn::Add(hn::Sub(lo, linear), hn::Set(d, quadratic.lo)),
          hn::Add(hn::Add(hi, linear), hn::Set(d, quadratic.hi))};
}

// h + w·max(0, v)³·u⁻⁴ (ProjectedFreeForm::boundNode's term for a perturbation bounded by v).
HWY_INLINE Lanes AddPerturbation(DD d, const Lanes& h, const Lanes& v, const Lanes& invU4,
                                 double w) {
  const VD zero = hn::Zero(d);
  const VD pLo = hn::Max(v.lo, zero), pHi = hn::Max(v.hi, zero);
  const VD cLo = hn::Mul(hn::Mul(pLo, pLo), pLo), cHi = hn::Mul(hn::Mul(pHi, pHi), pHi);
  // Interval product, then the weight.
  const VD p0 = hn::Mul(cLo, invU4.lo), p1 = hn::Mul(cLo, invU4.hi);
  const VD p2 = hn::Mul(cHi, invU4.lo), p3 = hn::Mul(cHi, invU4.hi);
  const VD mLo = hn::Min(hn::Min(p0, p1), hn::Min(p2, p3));
  const VD mHi = hn::Max(hn::Max(p0, p1), hn::Max(p2, p3));
  const VD vw = hn::Set(d, w);
  const VD tLo = hn::Mul(w >= 0 ? mLo : mHi, vw), tHi = hn::Mul(w >= 0 ? mHi : mLo, vw);
  return {hn::Add(h.lo, tLo), hn::Add(h.hi, tHi)};
}

// ProjectedFreeForm::boundNode for the lanes' z: the node's quadric plus its perturbations'
// w·max(0, H_c)³·u⁻⁴.
Lanes NodeBound(DD d, const ProjectedFreeForm::Node* nodes, uint32_t i, const Box& box,
                const Lanes& z, const Lanes& invU4) {
  Lanes h = QuadricBound(d, nodes[i].q, box, z);
  for (uint32_t c = i + 1; c < nodes[i].end; c = nodes[c].end)
    h = AddPerturbation(d, h, NodeBound(d, nodes, c, box, z, invU4), invU4, nodes[c].weight);
  return h;
}

// The root's bound: its quadric, and the terms of the perturbations `take` holds (the others are
// 0 here); `positive` gains the bits of those that may be positive in a lane of `lanes`.
Lanes RootBound(DD d, const ProjectedFreeForm::Node* nodes, const Box& box, const Lanes& z,
                const Lanes& invU4, uint64_t take, MD lanes, uint64_t& positive) {
  Lanes h = QuadricBound(d, nodes[0].q, box, z);
  const VD zero = hn::Zero(d);
  int k = 0;
  for (uint32_t c = 1; c < nodes[0].end; c = nodes[c].end, ++k) {
    if (k < 64 && (take >> k & 1) == 0) continue;
    const Lanes v = NodeBound(d, nodes, c, box, z, invU4);
    if (k < 64 && !hn::AllFalse(d, hn::And(lanes, hn::Gt(v.hi, zero))))
      positive |= uint64_t(1) << k;
    h = AddPerturbation(d, h, v, invU4, nodes[c].weight);
  }
  return h;
}

void SlabsHolding(const ProjectedFreeForm::Node* nodes, const Quadric* clips, size_t clipCount,
                  const double* w, Interval x, Interval y, double zlo, double zhi, int count,
                  bool* holds, uint64_t take, uint64_t* active) {
  uint64_t positive = 0;
  bool everything = false;  // a slab reaches behind the eye: no perturbation ruled out
  const DD d;
  const size_t n = hn::Lanes(d);
  const Box box{0.5 * (x.lo + x.hi), 0.5 * (y.lo + y.hi), 0.5 * (x.hi - x.lo), 0.5 * (y.hi - y.lo)};
  const Interval uxy = x * w[0] + y * w[1];  // u = x·w0 + y·w1 + z·w2 + w3
  const VD span = hn::Set(d, zhi - zlo), base = hn::Set(d, zlo), slabs = hn::Set(d, double(count));
  const VD zero = hn::Zero(d), one = hn::Set(d, 1.0);
  for (size_t s0 = 0; s0 < size_t(count); s0 += n) {
    const VD s = hn::Iota(d, double(s0));
    const Lanes z{hn::Add(base, hn::Div(hn::Mul(span, s), slabs)),
                  hn::Add(base, hn::Div(hn::Mul(span, hn::Add(s, one)), slabs))};
    const VD w2 = hn::Set(d, w[2]);
    const VD zwLo = hn::Mul(w[2] >= 0 ? z.lo : z.hi, w2),
             zwHi = hn::Mul(w[2] >= 0 ? z.hi : z.lo, w2);
    const VD uLo = hn::Add(hn::Add(hn::Set(d, uxy.lo), zwLo), hn::Set(d, w[3]));
    const VD uHi = hn::Add(hn::Add(hn::Set(d, uxy.hi), zwHi), hn::Set(d, w[3]));
    // Behind the eye (u ≤ 0 somewhere): the bound is everything.
    const auto behind = hn::Not(hn::Gt(uLo, zero));
    const VD lo2 = hn::Mul(uLo, uLo), hi2 = hn::Mul(uHi, uHi);
    const Lanes invU4{hn::Div(one, hn::Mul(hi2, hi2)), hn::Div(one, hn::Mul(lo2, lo2))};
    const MD inRange = hn::FirstN(d, size_t(count) - s0);
    if (!hn::AllFalse(d, hn::And(inRange, behind))) everything = true;
    Lanes h = RootBound(d, nodes, box, z, invU4, take, inRange, positive);
    for (size_t k = 0; k < clipCount; ++k) {
      const Lanes b = QuadricBound(d, clips[k], box, z);
      h = {hn::Min(h.lo, b.lo), hn::Min(h.hi, b.hi)};
    }
    // widened(h).containsZero()
    const VD margin = hn::Add(hn::Mul(hn::Set(d, 1e-12), hn::Add(hn::Abs(h.lo), hn::Abs(h.hi))),
                              hn::Set(d, 1e-300));
    const auto contains =
        hn::And(hn::Le(hn::Sub(h.lo, margin), zero), hn::Ge(hn::Add(h.hi, margin), zero));
    alignas(64) double out[16];
    hn::Store(hn::IfThenElseZero(hn::Or(behind, contains), one), d, out);
    for (size_t i = 0; i < n && s0 + i < size_t(count); ++i) holds[s0 + i] = out[i] != 0;
  }
  if (active) *active = everything ? take : positive;
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::freeform
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sv::freeform {

HWY_EXPORT(SlabsHolding);

void ProjectedFreeForm::slabsHolding(Interval x, Interval y, double zlo, double zhi, int count,
                                     bool* holds, uint64_t take, uint64_t* active) const {
  HWY_DYNAMIC_DISPATCH(SlabsHolding)
  (nodes_.data(), clips_.data(), clips_.size(), inverse_.m[3].data(), x, y, zlo, zhi,
   std::clamp(count, 1, 16), holds, take, active);
}

}  // namespace sv::freeform
#endif  // HWY_ONCE
