// ProjectedFreeForm::monotonicCrossings: the rays of a small window over which H is monotonic in
// depth — most of a free form's pixels — solved together, every ray a SIMD lane (Highway, per
// target). Each lane performs the operations of ProjectedFreeForm::ray, RayFunction::evaluate
// (freeform.cpp) and refineBracket (raycast.cpp) in the same order; lanes that have converged wait,
// masked, for the others, so a lane's result never depends on its neighbours or on the lane count.
//
// Based on: SPEC §12 (seed 003: at a leaf, the surface point along the ray).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "freeform/window_rays.cpp"
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

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

// The lanes' rays: per quadric (the nodes, then the clips) its b and c along z (alongZ in
// freeform.cpp; a is the quadric's own C), and u = u0 + u1·z.
struct Rays {
  const ProjectedFreeForm::Node* nodes;
  const Quadric* clips;
  size_t clipCount;
  const double* coefficients;  // [quadric][b, c][lane]
  size_t lanes;
  VD u0;
  double u1;
  VD b(size_t q, DD d) const { return hn::Load(d, coefficients + (2 * q) * lanes); }
  VD c(size_t q, DD d) const { return hn::Load(d, coefficients + (2 * q + 1) * lanes); }
};

// RayFunction::evaluateNode with the slope.
VD EvaluateNode(DD d, const Rays& r, uint32_t i, VD z, VD invU4, VD du4, VD& slope) {
  const double a = r.nodes[i].q.c[2];
  const VD b = r.b(i, d);
  VD h = hn::Add(hn::Mul(hn::Add(hn::Mul(hn::Set(d, a), z), b), z), r.c(i, d));
  slope = hn::Add(hn::Mul(hn::Set(d, 2 * a), z), b);
  for (uint32_t c = i + 1; c < r.nodes[i].end; c = r.nodes[c].end) {
    VD dv;
    const VD v = EvaluateNode(d, r, c, z, invU4, du4, dv);
    const MD positive = hn::Gt(v, hn::Zero(d));
    const VD w = hn::Set(d, r.nodes[c].weight), v2 = hn::Mul(v, v);
    const VD dh = hn::Mul(hn::Mul(hn::Mul(w, v2), v), invU4);
    const VD ds = hn::Mul(w, hn::Add(hn::Mul(hn::Mul(hn::Mul(hn::Set(d, 3.0), v2), dv), invU4),
                                     hn::Mul(hn::Mul(v2, v), du4)));
    h = hn::IfThenElse(positive, hn::Add(h, dh), h);
    slope = hn::IfThenElse(positive, hn::Add(slope, ds), slope);
  }
  return h;
}

// RayFunction::evaluate(z, slope).
HWY_INLINE VD Evaluate(DD d, const Rays& r, VD z, VD& slope) {
  const VD u = hn::Add(r.u0, hn::Mul(hn::Set(d, r.u1), z));
  const VD u2 = hn::Mul(u, u);
  const VD invU4 = hn::Div(hn::Set(d, 1.0), hn::Mul(u2, u2));
  const VD du4 = hn::Div(hn::Mul(hn::Set(d, -4 * r.u1), invU4), u);
  VD h = EvaluateNode(d, r, 0, z, invU4, du4, slope);
  const size_t nodeCount = r.nodes[0].end;
  for (size_t k = 0; k < r.clipCount; ++k) {
    const double a = r.clips[k].c[2];
    const VD b = r.b(nodeCount + k, d);
    const VD v = hn::Add(hn::Mul(hn::Add(hn::Mul(hn::Set(d, a), z), b), z), r.c(nodeCount + k, d));
    const MD below = hn::Lt(v, h);
    h = hn::IfThenElse(below, v, h);
    slope = hn::IfThenElse(below, hn::Add(hn::Mul(hn::Set(d, 2 * a), z), b), slope);
  }
  return h;
}

// b − fb·(b − a)/(fb − fa): the secant point of a bracket.
HWY_INLINE VD Secant(VD a, VD b, VD fa, VD fb) {
  return hn::Sub(b, hn::Div(hn::Mul(fb, hn::Sub(b, a)), hn::Sub(fb, fa)));
}
HWY_INLINE MD Within(VD z, VD a, VD b) { return hn::And(hn::Gt(z, a), hn::Lt(z, b)); }

void MonotonicCrossings(const ProjectedFreeForm::Node* nodes, const Quadric* clips,
                        size_t clipCount, const double* w, const double* x, const double* y,
                        double zlo, const double* zhi, int count, double guess, double* out) {
  const DD d;
  const size_t n = hn::Lanes(d);
  const size_t quadrics = nodes[0].end + clipCount;
  // Per thread, grown as needed; aligned to the vectors (padded by one line and rounded up).
  thread_local std::vector<double> storage;
  storage.resize(2 * quadrics * n + 8);
  double* const coefficients = reinterpret_cast<double*>(
      (reinterpret_cast<uintptr_t>(storage.data()) + 63) & ~uintptr_t(63));
  const VD half = hn::Set(d, 0.5), zero = hn::Zero(d), tolerance = hn::Set(d, kRootTolerance);
  const VD nan = hn::Set(d, std::numeric_limits<double>::quiet_NaN());
  alignas(64) double lx[16], ly[16], lz[16], result[16];
  for (size_t s0 = 0; s0 < size_t(count); s0 += n) {
    const size_t m = std::min(n, size_t(count) - s0);
    // Lanes past `count` are rays with an empty span (zhi = zlo): inactive throughout.
    for (size_t i = 0; i < n; ++i) {
      lx[i] = i < m ? x[s0 + i] : 0;
      ly[i] = i < m ? y[s0 + i] : 0;
      lz[i] = i < m ? zhi[s0 + i] : zlo;
    }
    const VD vx = hn::Load(d, lx), vy = hn::Load(d, ly);
    // ProjectedFreeForm::ray: each quadric along z.
    for (size_t q = 0; q < quadrics; ++q) {
      const auto& k = q < nodes[0].end ? nodes[q].q.c : clips[q - nodes[0].end].c;
      const VD b = hn::Add(hn::Add(hn::Mul(hn::Set(d, k[4]), vx), hn::Mul(hn::Set(d, k[5]), vy)),
                           hn::Set(d, k[8]));
      const VD cx = hn::Add(hn::Add(hn::Mul(hn::Set(d, k[0]), vx), hn::Mul(hn::Set(d, k[3]), vy)),
                            hn::Set(d, k[6]));
      const VD cy = hn::Add(hn::Mul(hn::Set(d, k[1]), vy), hn::Set(d, k[7]));
      const VD c = hn::Add(hn::Add(hn::Mul(cx, vx), hn::Mul(cy, vy)), hn::Set(d, k[9]));
      hn::Store(b, d, coefficients + (2 * q) * n);
      hn::Store(c, d, coefficients + (2 * q + 1) * n);
    }
    const Rays rays{nodes,
                    clips,
                    clipCount,
                    coefficients,
                    n,
                    hn::Add(hn::Add(hn::Mul(hn::Set(d, w[0]), vx), hn::Mul(hn::Set(d, w[1]), vy)),
                            hn::Set(d, w[3])),
                    w[2]};
    VD a = hn::Set(d, zlo), b = hn::Load(d, lz);
    VD slope;
    VD fa = Evaluate(d, rays, a, slope), fb = Evaluate(d, rays, b, slope);
    const MD insideA = hn::Ge(fa, zero);
    // A crossing: the span is not empty and H has opposite signs at its ends.
    const MD crossing = hn::And(hn::Lt(a, b), hn::Xor(insideA, hn::Ge(fb, zero)));
    MD live = crossing;
    VD z = hn::Set(d, guess);
    z = hn::IfThenElse(Within(z, a, b), z, Secant(a, b, fa, fb));
    z = hn::IfThenElse(Within(z, a, b), z, hn::Mul(half, hn::Add(a, b)));
    VD found = nan;
    MD converged = hn::Lt(zero, zero);  // none yet
    for (int i = 0; i < 60; ++i) {
      // Lanes whose bracket has closed stop here and take its near end.
      live = hn::AndNot(converged, hn::And(live, hn::Gt(hn::Sub(b, a), tolerance)));
      if (hn::AllFalse(d, live)) break;
      const VD fz = Evaluate(d, rays, z, slope);
      const MD same = hn::Not(hn::Xor(hn::Ge(fz, zero), insideA));
      a = hn::IfThenElse(hn::And(live, same), z, a);
      fa = hn::IfThenElse(hn::And(live, same), fz, fa);
      b = hn::IfThenElse(hn::AndNot(same, live), z, b);
      fb = hn::IfThenElse(hn::AndNot(same, live), fz, fb);
      const VD step = hn::IfThenElseZero(hn::Ne(slope, zero), hn::Div(fz, slope));
      VD next = hn::Sub(z, step);
      const MD done = hn::And(live, hn::Le(hn::Abs(step), tolerance));
      found = hn::IfThenElse(done, hn::Min(hn::Max(next, a), b), found);
      converged = hn::Or(converged, done);
      next = hn::IfThenElse(
          Within(next, a, b), next,
          hn::IfThenElse(hn::Ne(fb, fa), Secant(a, b, fa, fb), hn::Mul(half, hn::Add(a, b))));
      next = hn::IfThenElse(Within(next, a, b), next, hn::Mul(half, hn::Add(a, b)));
      z = hn::IfThenElse(live, next, z);
    }
    // Lanes with a crossing that did not converge by a Newton step: the bracket's near end.
    found = hn::IfThenElse(hn::AndNot(converged, crossing), a, found);
    hn::Store(found, d, result);
    std::copy_n(result, m, out + s0);
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::freeform
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sv::freeform {

HWY_EXPORT(MonotonicCrossings);

void ProjectedFreeForm::monotonicCrossings(const double* x, const double* y, double zlo,
                                           const double* zhi, int count, double guess,
                                           double* z) const {
  HWY_DYNAMIC_DISPATCH(MonotonicCrossings)
  (nodes_.data(), clips_.data(), clips_.size(), inverse_.m[3].data(), x, y, zlo, zhi,
   std::clamp(count, 0, 16), guess, z);
}

}  // namespace sv::freeform
#endif  // HWY_ONCE
