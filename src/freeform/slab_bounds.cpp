// Bounds of the free-form caster in SIMD lanes (Highway, per target). ProjectedFreeForm::
// slabsHolding: one screen window's slabs in depth (the binary tree in depth of Caster::cell,
// raycast.cpp, and of FreeFormPass::markTiles), every slab a lane; the window's x and y are the
// same for all its slabs, so what depends on them alone — per quadric, its centre's quadratic in z
// and the gradient's linear terms — is worked out once per window instead of once per slab.
// ProjectedFreeForm::boundWindows: the bound with its slope of several windows over one depth
// range (the four 4×4 windows of an 8×8 cell), every window a lane.
//
// Each lane performs the operations of ProjectedFreeForm::bound (freeform.cpp) and Quadric::bound
// (quadric.cpp) in the same order, and the build does not contract them into FMAs, so every target
// answers as the scalar bound does, bit for bit (tests/freeform checks each compiled target).
//
// Based on: SPEC §12 (seed 003: binary subdivision in depth, cells rejected by bounds).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "freeform/slab_bounds.cpp"
// clang-format off: foreach_target.h first, the per-target -inl.h headers after it
#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"
// clang-format on

#include <algorithm>
#include <cmath>
#include <limits>

#include "freeform/freeform.h"
#include "freeform/interval_lanes-inl.h"

HWY_BEFORE_NAMESPACE();
namespace sv::freeform {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

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
HWY_INLINE Lanes WithPerturbation(DD d, const Lanes& h, const Lanes& v, const Lanes& invU4,
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
    h = WithPerturbation(d, h, NodeBound(d, nodes, c, box, z, invU4), invU4, nodes[c].weight);
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
    h = WithPerturbation(d, h, v, invU4, nodes[c].weight);
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

// --- Windows of one depth range, a window per lane (ProjectedFreeForm::boundWindows) ---

// Per lane, the window x × y as Quadric::bound reads it.
struct Boxes {
  VD xc, yc, rx, ry;
  Lanes x, y;
};

// Quadric::bound(x, y, z) for the lanes' windows and one z.
Lanes BoxBound(DD d, const Quadric& q, const Boxes& box, Interval z) {
  const auto& c = q.c;
  const auto k = [&](int i) { return hn::Set(d, c[size_t(i)]); };
  const VD b = hn::Add(hn::Add(hn::Mul(k(4), box.xc), hn::Mul(k(5), box.yc)), k(8));
  const VD kk = hn::Add(
      hn::Add(hn::Mul(hn::Add(hn::Add(hn::Mul(k(0), box.xc), hn::Mul(k(3), box.yc)), k(6)), box.xc),
              hn::Mul(hn::Add(hn::Mul(k(1), box.yc), k(7)), box.yc)),
      k(9));
  // quadraticRange(C, b, k, z)
  const auto f = [&](VD v) { return hn::Add(hn::Mul(hn::Add(hn::Mul(k(2), v), b), v), kk); };
  const VD zlo = hn::Set(d, z.lo), zhi = hn::Set(d, z.hi);
  const VD fLo = f(zlo), fHi = f(zhi);
  VD lo = hn::Min(fLo, fHi), hi = hn::Max(fLo, fHi);
  if (c[2] != 0) {
    const VD vertex = hn::Div(hn::Neg(b), hn::Set(d, 2 * c[2]));
    const MD within = hn::And(hn::Lt(zlo, vertex), hn::Lt(vertex, zhi));
    const VD fv = f(vertex);
    lo = hn::IfThenElse(within, hn::Min(lo, fv), lo);
    hi = hn::IfThenElse(within, hn::Max(hi, fv), hi);
  }
  const VD gx0 =
      hn::Add(hn::Add(hn::Mul(hn::Set(d, 2 * c[0]), box.xc), hn::Mul(k(3), box.yc)), k(6));
  const VD gy0 =
      hn::Add(hn::Add(hn::Mul(hn::Set(d, 2 * c[1]), box.yc), hn::Mul(k(3), box.xc)), k(7));
  const VD gx =
      hn::Max(hn::Abs(hn::Add(gx0, hn::Mul(k(4), zlo))), hn::Abs(hn::Add(gx0, hn::Mul(k(4), zhi))));
  const VD gy =
      hn::Max(hn::Abs(hn::Add(gy0, hn::Mul(k(5), zlo))), hn::Abs(hn::Add(gy0, hn::Mul(k(5), zhi))));
  const VD linear = hn::Add(hn::Mul(gx, box.rx), hn::Mul(gy, box.ry));
  // {0, rx²}·A + {0, ry²}·B + {−1, 1}·(|D|·rx·ry)
  const VD zero = hn::Zero(d);
  const Lanes a2 = Scale(d, {zero, hn::Mul(box.rx, box.rx)}, c[0]);
  const Lanes b2 = Scale(d, {zero, hn::Mul(box.ry, box.ry)}, c[1]);
  const VD dd = hn::Mul(hn::Mul(hn::Set(d, std::fabs(c[3])), box.rx), box.ry);
  const Lanes quadratic = Sum(Sum(a2, b2), {hn::Neg(dd), dd});
  return {hn::Add(hn::Sub(lo, linear), quadratic.lo), hn::Add(hn::Add(hi, linear), quadratic.hi)};
}

// z·2C + x·E + y·F + I: a quadric's ∂/∂z over the lanes' windows.
HWY_INLINE Lanes SlopeZ(DD d, const Quadric& q, const Boxes& box, Interval z) {
  const Interval zc = z * (2 * q.c[2]);
  return Sum(Sum(Sum({hn::Set(d, zc.lo), hn::Set(d, zc.hi)}, Scale(d, box.x, q.c[4])),
                 Scale(d, box.y, q.c[5])),
             {hn::Set(d, q.c[8]), hn::Set(d, q.c[8])});
}

struct Powers {  // u⁻⁴ and u⁻⁵ per lane
  Lanes u4, u5;
};

// ProjectedFreeForm::boundNodeSlope for the lanes' windows.
void BoxNodeSlope(DD d, const ProjectedFreeForm::Node* nodes, uint32_t i, const Boxes& box,
                  Interval z, const Powers& inv, double u1, Lanes& value, Lanes& slope) {
  value = BoxBound(d, nodes[i].q, box, z);
  slope = SlopeZ(d, nodes[i].q, box, z);
  for (uint32_t c = i + 1; c < nodes[i].end; c = nodes[c].end) {
    Lanes v, dv;
    BoxNodeSlope(d, nodes, c, box, z, inv, u1, v, dv);
    AddPerturbation(d, v, dv, nodes[c].weight, inv.u4, inv.u5, u1, value, slope);
  }
}

void BoundWindows(const ProjectedFreeForm::Node* nodes, const Quadric* clips, size_t clipCount,
                  const double* w, const Interval* x, const Interval* y, int count, Interval z,
                  uint64_t take, Interval* value, Interval* slope, uint64_t* active) {
  const DD d;
  const size_t n = hn::Lanes(d);
  const double inf = std::numeric_limits<double>::infinity();
  for (size_t s0 = 0; s0 < size_t(count); s0 += n) {
    const size_t m = std::min(n, size_t(count) - s0);
    alignas(64) double in[4][16] = {};
    for (size_t i = 0; i < m; ++i) {
      in[0][i] = x[s0 + i].lo, in[1][i] = x[s0 + i].hi;
      in[2][i] = y[s0 + i].lo, in[3][i] = y[s0 + i].hi;
    }
    Boxes box;
    box.x = {hn::Load(d, in[0]), hn::Load(d, in[1])};
    box.y = {hn::Load(d, in[2]), hn::Load(d, in[3])};
    const VD half = hn::Set(d, 0.5);
    box.xc = hn::Mul(half, hn::Add(box.x.lo, box.x.hi));
    box.yc = hn::Mul(half, hn::Add(box.y.lo, box.y.hi));
    box.rx = hn::Mul(half, hn::Sub(box.x.hi, box.x.lo));
    box.ry = hn::Mul(half, hn::Sub(box.y.hi, box.y.lo));
    // u = x·w0 + y·w1 + z·w2 + w3
    const Interval zw = z * w[2];
    const Lanes u = Sum(Sum(Sum(Scale(d, box.x, w[0]), Scale(d, box.y, w[1])),
                            {hn::Set(d, zw.lo), hn::Set(d, zw.hi)}),
                        {hn::Set(d, w[3]), hn::Set(d, w[3])});
    const MD front = hn::Gt(u.lo, hn::Zero(d));
    const VD one = hn::Set(d, 1.0), lo2 = hn::Mul(u.lo, u.lo), hi2 = hn::Mul(u.hi, u.hi);
    const Powers inv{{hn::Div(one, hn::Mul(hi2, hi2)), hn::Div(one, hn::Mul(lo2, lo2))},
                     {hn::Div(one, hn::Mul(hn::Mul(hi2, hi2), u.hi)),
                      hn::Div(one, hn::Mul(hn::Mul(lo2, lo2), u.lo))}};
    // The root, noting per lane which perturbations may be positive.
    uint64_t lanesActive[16];
    std::fill_n(lanesActive, n, take);
    Lanes h = BoxBound(d, nodes[0].q, box, z), dh = SlopeZ(d, nodes[0].q, box, z);
    int k = 0;
    for (uint32_t c = 1; c < nodes[0].end; c = nodes[c].end, ++k) {
      if (k < 64 && (take >> k & 1) == 0) continue;
      Lanes v, dv;
      BoxNodeSlope(d, nodes, c, box, z, inv, w[2], v, dv);
      if (k < 64) {
        alignas(64) double hiv[16];
        hn::Store(v.hi, d, hiv);
        for (size_t i = 0; i < m; ++i)
          if (hiv[i] <= 0) lanesActive[i] &= ~(uint64_t(1) << k);
      }
      AddPerturbation(d, v, dv, nodes[c].weight, inv.u4, inv.u5, w[2], h, dh);
    }
    for (size_t j = 0; j < clipCount; ++j) {  // freeform.cpp's takeMinimum
      TakeMinimum(BoxBound(d, clips[j], box, z), SlopeZ(d, clips[j], box, z), h, dh);
    }
    h = Widened(d, h);
    dh = Widened(d, dh);
    alignas(64) double out[4][16], inFront[16];
    hn::Store(h.lo, d, out[0]);
    hn::Store(h.hi, d, out[1]);
    hn::Store(dh.lo, d, out[2]);
    hn::Store(dh.hi, d, out[3]);
    hn::Store(hn::IfThenElseZero(front, one), d, inFront);
    for (size_t i = 0; i < m; ++i) {
      // Behind the eye (u ≤ 0 somewhere): everything, and no perturbation ruled out.
      const bool ok = inFront[i] != 0;
      value[s0 + i] = ok ? Interval{out[0][i], out[1][i]} : Interval{-inf, inf};
      slope[s0 + i] = ok ? Interval{out[2][i], out[3][i]} : Interval{-inf, inf};
      active[s0 + i] = ok ? lanesActive[i] : take;
    }
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::freeform
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sv::freeform {

HWY_EXPORT(SlabsHolding);
HWY_EXPORT(BoundWindows);

void ProjectedFreeForm::boundWindows(const Interval* x, const Interval* y, int count, Interval z,
                                     uint64_t take, Interval* value, Interval* slope,
                                     uint64_t* active) const {
  HWY_DYNAMIC_DISPATCH(BoundWindows)
  (nodes_.data(), clips_.data(), clips_.size(), inverse_.m[3].data(), x, y,
   std::clamp(count, 0, 16), z, take, value, slope, active);
}

void ProjectedFreeForm::slabsHolding(Interval x, Interval y, double zlo, double zhi, int count,
                                     bool* holds, uint64_t take, uint64_t* active) const {
  HWY_DYNAMIC_DISPATCH(SlabsHolding)
  (nodes_.data(), clips_.data(), clips_.size(), inverse_.m[3].data(), x, y, zlo, zhi,
   std::clamp(count, 1, 16), holds, take, active);
}

}  // namespace sv::freeform
#endif  // HWY_ONCE
