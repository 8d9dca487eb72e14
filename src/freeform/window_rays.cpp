// Rays solved together, every ray a SIMD lane (Highway, per target): a 4×4 window's —
// ProjectedFreeForm::monotonicCrossings, where H is monotonic in depth over the window, and
// provenCrossings / piecewiseCrossings, where it may turn (silhouettes), each ray bounding its own
// pieces of depth (BoundLanes: each quadric's exact range along the ray, the perturbations
// through their quadrics' bounds); quadricCrossings and quadricHits, the closed form where no
// perturbation reaches the rays; and crossingBracket, one ray's span split eight pieces at a time.
// Each lane performs the operations of ProjectedFreeForm::ray, RayFunction::evaluate
// (freeform.cpp) and refineBracket (raycast.cpp) in the same order; lanes that are done wait,
// masked, for the others, so a lane's result never depends on its neighbours or on the lane count.
//
// Based on: SPEC §12 (seed 003: at a leaf, the surface point along the ray).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "freeform/window_rays.cpp"
// clang-format off: foreach_target.h first, the per-target -inl.h headers after it
#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"
// clang-format on

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/masked_store-inl.h"
#include "freeform/freeform.h"
#include "freeform/interval_lanes-inl.h"

HWY_BEFORE_NAMESPACE();
namespace sv::freeform {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;
using core::HWY_NAMESPACE::storeWhere;

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
  uint64_t active;  // the root's perturbations taken into H (ProjectedFreeForm::bound)
  VD b(size_t q, DD d) const { return hn::Load(d, coefficients + (2 * q) * lanes); }
  VD c(size_t q, DD d) const { return hn::Load(d, coefficients + (2 * q + 1) * lanes); }
  // Whether child c, the k-th perturbation of node i, is part of H: every child of a
  // perturbation is; of the root, those `active` holds (the rest are 0 over the rays).
  bool takes(uint32_t i, int k) const { return i != 0 || k >= 64 || (active >> k & 1) != 0; }
};

// Newton's method along a ray is a chain of dependent steps — each waits on its evaluation and
// on two divisions — so kGroup vectors of rays are solved together, their chains interleaved
// operation by operation (each lane still does exactly the single-vector operations: same bits;
// faster than one vector at a time, docs/performance.md "Free forms").
constexpr int kGroup = 2;

// RayFunction::evaluateNode with the slope, for K vectors' rays r[k] at z[k].
template <int K>
void EvaluateNodes(DD d, const Rays* r, uint32_t i, const VD* z, const VD* invU4, const VD* du4,
                   VD* h, VD* slope) {
  const double a = r[0].nodes[i].q.c[2];
  for (int k = 0; k < K; ++k) {
    const VD b = r[k].b(i, d);
    h[k] = hn::Add(hn::Mul(hn::Add(hn::Mul(hn::Set(d, a), z[k]), b), z[k]), r[k].c(i, d));
    slope[k] = hn::Add(hn::Mul(hn::Set(d, 2 * a), z[k]), b);
  }
  int n = 0;
  for (uint32_t c = i + 1; c < r[0].nodes[i].end; c = r[0].nodes[c].end) {
    if (!r[0].takes(i, n++)) continue;
    VD v[K], dv[K];
    EvaluateNodes<K>(d, r, c, z, invU4, du4, v, dv);
    const VD w = hn::Set(d, r[0].nodes[c].weight);
    for (int k = 0; k < K; ++k) {
      const MD positive = hn::Gt(v[k], hn::Zero(d));
      const VD v2 = hn::Mul(v[k], v[k]);
      const VD dh = hn::Mul(hn::Mul(hn::Mul(w, v2), v[k]), invU4[k]);
      const VD ds =
          hn::Mul(w, hn::Add(hn::Mul(hn::Mul(hn::Mul(hn::Set(d, 3.0), v2), dv[k]), invU4[k]),
                             hn::Mul(hn::Mul(v2, v[k]), du4[k])));
      h[k] = hn::IfThenElse(positive, hn::Add(h[k], dh), h[k]);
      slope[k] = hn::IfThenElse(positive, hn::Add(slope[k], ds), slope[k]);
    }
  }
}

// RayFunction::evaluate(z, slope) for K vectors' rays r[k] at z[k].
template <int K>
HWY_INLINE void EvaluateGroup(DD d, const Rays* r, const VD* z, VD* h, VD* slope) {
  VD invU4[K], du4[K];
  for (int k = 0; k < K; ++k) {
    const VD u = hn::Add(r[k].u0, hn::Mul(hn::Set(d, r[k].u1), z[k]));
    const VD u2 = hn::Mul(u, u);
    invU4[k] = hn::Div(hn::Set(d, 1.0), hn::Mul(u2, u2));
    du4[k] = hn::Div(hn::Mul(hn::Set(d, -4 * r[k].u1), invU4[k]), u);
  }
  EvaluateNodes<K>(d, r, 0, z, invU4, du4, h, slope);
  const size_t nodeCount = r[0].nodes[0].end;
  for (size_t c = 0; c < r[0].clipCount; ++c) {
    const double a = r[0].clips[c].c[2];
    for (int k = 0; k < K; ++k) {
      const VD b = r[k].b(nodeCount + c, d);
      const VD v = hn::Add(hn::Mul(hn::Add(hn::Mul(hn::Set(d, a), z[k]), b), z[k]),
                           r[k].c(nodeCount + c, d));
      const MD below = hn::Lt(v, h[k]);
      h[k] = hn::IfThenElse(below, v, h[k]);
      slope[k] = hn::IfThenElse(below, hn::Add(hn::Mul(hn::Set(d, 2 * a), z[k]), b), slope[k]);
    }
  }
}

// RayFunction::evaluate(z, slope) for one vector of rays.
HWY_INLINE VD Evaluate(DD d, const Rays& r, VD z, VD& slope) {
  VD h;
  EvaluateGroup<1>(d, &r, &z, &h, &slope);
  return h;
}

// b − fb·(b − a)/(fb − fa): the secant point of a bracket.
HWY_INLINE VD Secant(VD a, VD b, VD fa, VD fb) {
  return hn::Sub(b, hn::Div(hn::Mul(fb, hn::Sub(b, a)), hn::Sub(fb, fa)));
}
HWY_INLINE MD Within(VD z, VD a, VD b) { return hn::And(hn::Gt(z, a), hn::Lt(z, b)); }

// quadraticRange (quadric.h) of a·z² + b·z + c over the lanes' [zA, zB], b and c per lane.
HWY_INLINE Lanes QuadraticRange(DD d, double a, VD b, VD c, VD zA, VD zB) {
  const VD va = hn::Set(d, a);
  const auto f = [&](VD v) { return hn::Add(hn::Mul(hn::Add(hn::Mul(va, v), b), v), c); };
  const VD fA = f(zA), fB = f(zB);
  VD lo = hn::Min(fA, fB), hi = hn::Max(fA, fB);
  if (a != 0) {
    const VD vertex = hn::Div(hn::Neg(b), hn::Set(d, 2 * a));
    const MD within = hn::And(hn::Lt(zA, vertex), hn::Lt(vertex, zB));
    const VD fv = f(vertex);
    lo = hn::IfThenElse(within, hn::Min(lo, fv), lo);
    hi = hn::IfThenElse(within, hn::Max(hi, fv), hi);
  }
  return {lo, hi};
}

// A node's bound and slope bound over the lanes' [zA, zB] of their rays: its quadratic's exact
// range, plus its perturbations' terms (freeform.cpp's addPerturbation).
void NodeBoundSlope(DD d, const Rays& r, uint32_t i, const Lanes& z, const Lanes& u4,
                    const Lanes& u5, Lanes& value, Lanes& slope) {
  const double a = r.nodes[i].q.c[2];
  const VD b = r.b(i, d);
  value = QuadraticRange(d, a, b, r.c(i, d), z.lo, z.hi);
  const Lanes s = Scale(d, z, 2 * a);
  slope = {hn::Add(s.lo, b), hn::Add(s.hi, b)};
  int k = 0;
  for (uint32_t c = i + 1; c < r.nodes[i].end; c = r.nodes[c].end) {
    if (!r.takes(i, k++)) continue;
    Lanes v, dv;
    NodeBoundSlope(d, r, c, z, u4, u5, v, dv);
    AddPerturbation(d, v, dv, r.nodes[c].weight, u4, u5, r.u1, value, slope);
  }
}

// A range containing H over the lanes' [zA, zB] of their rays, and one of dH/dz there, widened for
// rounding (where the slope excludes 0, H is monotonic and has at most one zero); false lanes: u ≤
// 0 somewhere (behind the eye), where the bound is everything.
MD BoundLanes(DD d, const Rays& r, const Lanes& z, Lanes& value, Lanes& slope) {
  const Lanes zu = Scale(d, z, r.u1);
  const Lanes u{hn::Add(zu.lo, r.u0), hn::Add(zu.hi, r.u0)};
  const VD one = hn::Set(d, 1.0), lo2 = hn::Mul(u.lo, u.lo), hi2 = hn::Mul(u.hi, u.hi);
  const Lanes u4{hn::Div(one, hn::Mul(hi2, hi2)), hn::Div(one, hn::Mul(lo2, lo2))};
  const Lanes u5{hn::Div(one, hn::Mul(hn::Mul(hi2, hi2), u.hi)),
                 hn::Div(one, hn::Mul(hn::Mul(lo2, lo2), u.lo))};
  NodeBoundSlope(d, r, 0, z, u4, u5, value, slope);
  const size_t nodeCount = r.nodes[0].end;
  for (size_t k = 0; k < r.clipCount; ++k) {
    const double a = r.clips[k].c[2];
    const VD b = r.b(nodeCount + k, d);
    const Lanes clip = QuadraticRange(d, a, b, r.c(nodeCount + k, d), z.lo, z.hi);
    const Lanes s = Scale(d, z, 2 * a);
    TakeMinimum(clip, {hn::Add(s.lo, b), hn::Add(s.hi, b)}, value, slope);
  }
  value = Widened(d, value);
  slope = Widened(d, slope);
  return hn::Gt(u.lo, hn::Zero(d));
}

// Per-thread storage for the lanes' coefficients, aligned to the vectors.
double* CoefficientStorage(size_t doubles) {
  thread_local std::vector<double> storage;
  storage.resize(doubles + 8);  // padded by one line and rounded up
  return reinterpret_cast<double*>((reinterpret_cast<uintptr_t>(storage.data()) + 63) &
                                   ~uintptr_t(63));
}

// Quadric q along the lanes' rays (vx, vy): C·z² + b·z + c (ProjectedFreeForm::ray's b and c).
HWY_INLINE void AlongZ(DD d, const Quadric& q, VD vx, VD vy, VD& b, VD& c) {
  const auto& k = q.c;
  b = hn::Add(hn::Add(hn::Mul(hn::Set(d, k[4]), vx), hn::Mul(hn::Set(d, k[5]), vy)),
              hn::Set(d, k[8]));
  const VD cx = hn::Add(hn::Add(hn::Mul(hn::Set(d, k[0]), vx), hn::Mul(hn::Set(d, k[3]), vy)),
                        hn::Set(d, k[6]));
  const VD cy = hn::Add(hn::Mul(hn::Set(d, k[1]), vy), hn::Set(d, k[7]));
  c = hn::Add(hn::Add(hn::Mul(cx, vx), hn::Mul(cy, vy)), hn::Set(d, k[9]));
}

// ProjectedFreeForm::ray for the lanes' rays (vx, vy): each quadric along z, into `coefficients`.
Rays SetUpRays(DD d, const ProjectedFreeForm::Node* nodes, const Quadric* clips, size_t clipCount,
               const double* w, uint64_t active, VD vx, VD vy, double* coefficients) {
  const size_t n = hn::Lanes(d);
  const Rays rays{nodes,
                  clips,
                  clipCount,
                  coefficients,
                  n,
                  hn::Add(hn::Add(hn::Mul(hn::Set(d, w[0]), vx), hn::Mul(hn::Set(d, w[1]), vy)),
                          hn::Set(d, w[3])),
                  w[2],
                  active};
  const auto alongZ = [&](size_t q) {
    VD b, c;
    AlongZ(d, q < nodes[0].end ? nodes[q].q : clips[q - nodes[0].end], vx, vy, b, c);
    hn::Store(b, d, coefficients + (2 * q) * n);
    hn::Store(c, d, coefficients + (2 * q + 1) * n);
  };
  // The root, the perturbations taken into H with their own, and the clips.
  alongZ(0);
  int k = 0;
  for (uint32_t c = 1; c < nodes[0].end; c = nodes[c].end)
    if (rays.takes(0, k++))
      for (uint32_t q = c; q < nodes[c].end; ++q) alongZ(q);
  for (size_t q = nodes[0].end; q < nodes[0].end + clipCount; ++q) alongZ(q);
  return rays;
}

// newtonConverged (freeform.h) for the lanes' step lengths s and the steps before them.
HWY_INLINE MD NewtonConverged(DD d, VD s, VD previous) {
  const VD cubed = hn::Mul(hn::Mul(s, s), s);
  const VD bound = hn::Mul(hn::Mul(hn::Set(d, 0.01 * kRootTolerance), previous), previous);
  return hn::Or(hn::Le(s, hn::Set(d, kRootTolerance)),
                hn::And(hn::Lt(s, previous), hn::Le(cubed, bound)));
}

// refineBracket (raycast.cpp) in the lanes where `crossing` holds — brackets [a, b] with
// inside(fa) ≠ inside(fb) — from `guess` where it lies inside; NaN in the other lanes.
VD Refine(DD d, const Rays& rays, VD a, VD b, VD fa, VD fb, MD crossing, VD guess) {
  const VD half = hn::Set(d, 0.5), zero = hn::Zero(d), tolerance = hn::Set(d, kRootTolerance);
  const MD insideA = hn::Ge(fa, zero);
  MD live = crossing;
  VD z = hn::IfThenElse(Within(guess, a, b), guess, Secant(a, b, fa, fb));
  z = hn::IfThenElse(Within(z, a, b), z, hn::Mul(half, hn::Add(a, b)));
  VD found = hn::Set(d, std::numeric_limits<double>::quiet_NaN()), slope;
  MD converged = hn::Lt(zero, zero);  // none yet
  VD previous = zero;                 // the last Newton step's length (0: none)
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
    const VD s = hn::Abs(step);
    const MD done = hn::And(live, NewtonConverged(d, s, previous));
    found = hn::IfThenElse(done, hn::Min(hn::Max(next, a), b), found);
    converged = hn::Or(converged, done);
    const MD newton = Within(next, a, b);  // else safeguarded: no Newton step taken
    previous = hn::IfThenElseZero(newton, s);
    next = hn::IfThenElse(
        newton, next,
        hn::IfThenElse(hn::Ne(fb, fa), Secant(a, b, fa, fb), hn::Mul(half, hn::Add(a, b))));
    next = hn::IfThenElse(Within(next, a, b), next, hn::Mul(half, hn::Add(a, b)));
    z = hn::IfThenElse(live, next, z);
  }
  // Lanes with a crossing that did not converge by a Newton step: the bracket's near end.
  return hn::IfThenElse(hn::AndNot(converged, crossing), a, found);
}

// Values v[s0 … s0 + m) into the lanes, `fill` past them. A whole vector is loaded as it is: a
// vector load of lanes just written one by one waits for the stores (docs/performance.md,
// "Pitfalls").
HWY_INLINE VD LoadPadded(DD d, const double* v, size_t s0, size_t m, double fill) {
  if (m == hn::Lanes(d)) return hn::LoadU(d, v + s0);
  alignas(64) double lanes[16];
  for (size_t i = 0; i < hn::Lanes(d); ++i) lanes[i] = i < m ? v[s0 + i] : fill;
  return hn::Load(d, lanes);
}

// The first m lanes of v to out[0 … m).
HWY_INLINE void StoreFirst(DD d, VD v, size_t m, double* out) {
  if (m == hn::Lanes(d)) return hn::StoreU(v, d, out);
  alignas(64) double lanes[16];
  hn::Store(v, d, lanes);
  std::copy_n(lanes, m, out);
}

// The lanes' own rays, x[i], y[i] and span ends zhi[i] for i < count, `n` at a time: lanes past
// `count` are rays with an empty span (zhi = zlo), inactive throughout.
template <class Body>
void ForEachVector(DD d, const double* x, const double* y, double zlo, const double* zhi, int count,
                   const Body& body) {
  const size_t n = hn::Lanes(d);
  for (size_t s0 = 0; s0 < size_t(count); s0 += n) {
    const size_t m = std::min(n, size_t(count) - s0);
    body(s0, m, LoadPadded(d, x, s0, m, 0), LoadPadded(d, y, s0, m, 0),
         LoadPadded(d, zhi, s0, m, zlo));
  }
}

// Newton alone from guesses g[k] (lanes span[k], where g lies in [a, b[k]]), the kGroup vectors
// together: up to four steps, a lane settled when a step lands in [a, b] and has converged
// (newtonConverged), its zero in found[k] (NaN in the other lanes); lanes whose step leaves the
// span, or slow ones, stay unsettled. A lane's steps are its own: others still going change
// nothing in it.
HWY_INLINE void NewtonFromGuesses(DD d, const Rays* rays, VD a, const VD* b, const VD* g,
                                  const MD* span, VD* found, MD* settled) {
  const VD zero = hn::Zero(d);
  MD open[kGroup];
  VD z[kGroup], previous[kGroup];
  bool any = false;
  for (int k = 0; k < kGroup; ++k) {
    open[k] = hn::And(span[k], Within(g[k], a, b[k]));
    settled[k] = hn::Lt(zero, zero);
    z[k] = g[k];
    previous[k] = zero;
    found[k] = hn::Set(d, std::numeric_limits<double>::quiet_NaN());
    any = any || !hn::AllFalse(d, open[k]);
  }
  for (int i = 0; i < 4 && any; ++i) {
    VD fz[kGroup], slope[kGroup];
    EvaluateGroup<kGroup>(d, rays, z, fz, slope);
    any = false;
    for (int k = 0; k < kGroup; ++k) {
      const VD step = hn::Div(fz[k], slope[k]), next = hn::Sub(z[k], step), s = hn::Abs(step);
      const MD converged = hn::And(hn::And(open[k], hn::And(hn::Ge(next, a), hn::Le(next, b[k]))),
                                   NewtonConverged(d, s, previous[k]));
      found[k] = hn::IfThenElse(converged, next, found[k]);
      settled[k] = hn::Or(settled[k], converged);
      open[k] = hn::AndNot(converged, hn::And(open[k], Within(next, a, b[k])));
      previous[k] = s;
      z[k] = next;
      any = any || !hn::AllFalse(d, open[k]);
    }
  }
}

// The lanes' own rays, x[i], y[i] and span ends zhi[i] for i < count, kGroup vectors of `n` at a
// time, each set up (SetUpRays) in its own part of `coefficients` (`stride` doubles each): lanes
// past `count` are rays with an empty span (zhi = zlo), inactive throughout. body(s0, m, rays, vz)
// takes arrays of kGroup: vector k's rays begin at ray s0[k], m[k] of them its own (0: none).
template <class Body>
void ForEachGroup(DD d, const ProjectedFreeForm::Node* nodes, const Quadric* clips,
                  size_t clipCount, const double* w, uint64_t active, const double* x,
                  const double* y, double zlo, const double* zhi, int count, double* coefficients,
                  size_t stride, const Body& body) {
  const size_t n = hn::Lanes(d);
  for (size_t g0 = 0; g0 < size_t(count); g0 += kGroup * n) {
    Rays rays[kGroup];
    VD vz[kGroup];
    size_t s0[kGroup], m[kGroup];
    for (int k = 0; k < kGroup; ++k) {
      s0[k] = g0 + size_t(k) * n;
      m[k] = s0[k] < size_t(count) ? std::min(n, size_t(count) - s0[k]) : 0;
      vz[k] = LoadPadded(d, zhi, s0[k], m[k], zlo);
      rays[k] = SetUpRays(d, nodes, clips, clipCount, w, active, LoadPadded(d, x, s0[k], m[k], 0),
                          LoadPadded(d, y, s0[k], m[k], 0), coefficients + size_t(k) * stride);
    }
    body(s0, m, rays, vz);
  }
}

void MonotonicCrossings(const ProjectedFreeForm::Node* nodes, const Quadric* clips,
                        size_t clipCount, const double* w, const double* x, const double* y,
                        double zlo, const double* zhi, int count, const double* guess, double* out,
                        uint64_t active) {
  const DD d;
  const size_t stride = 2 * (nodes[0].end + clipCount) * hn::Lanes(d);
  double* coefficients = CoefficientStorage(kGroup * stride);
  ForEachGroup(d, nodes, clips, clipCount, w, active, x, y, zlo, zhi, count, coefficients, stride,
               [&](const size_t* s0, const size_t* m, const Rays* rays, const VD* b) {
                 const VD a = hn::Set(d, zlo), zero = hn::Zero(d);
                 VD g[kGroup], found[kGroup];
                 MD span[kGroup], settled[kGroup];
                 for (int k = 0; k < kGroup; ++k) {
                   g[k] = LoadPadded(d, guess, s0[k], m[k], 0);
                   span[k] = hn::Lt(a, b[k]);
                 }
                 // Step 1: Newton alone from the guesses. H is monotonic over each span, so a zero
                 // Newton converges to inside it is the span's only crossing — no need to bracket
                 // it first.
                 NewtonFromGuesses(d, rays, a, b, g, span, found, settled);
                 for (int k = 0; k < kGroup && m[k] > 0; ++k) {
                   // Step 2: the other rays — no guess inside, Newton leaving the span or slow —
                   // bracketed: H has opposite signs at the span's ends, refined as refineBracket
                   // refines.
                   const MD rest = hn::AndNot(settled[k], span[k]);
                   if (!hn::AllFalse(d, rest)) {
                     VD slope;
                     const VD fa = Evaluate(d, rays[k], a, slope),
                              fb = Evaluate(d, rays[k], b[k], slope);
                     const MD crossing = hn::And(rest, hn::Xor(hn::Ge(fa, zero), hn::Ge(fb, zero)));
                     found[k] = hn::IfThenElse(settled[k], found[k],
                                               Refine(d, rays[k], a, b[k], fa, fb, crossing, g[k]));
                   }
                   StoreFirst(d, found[k], m[k], out + s0[k]);
                 }
               });
}

// The lanes' first crossings of H = min(root, clips) in (zlo, end], the quadrics (the root, then
// the clips: `quadrics` ≤ kMaxQuadrics of them) given along the rays as squared[j]·z² + b[j]·z +
// c[j] (AlongZ): NaN where there is none. ProjectedFreeForm::quadricCrossings.
constexpr size_t kMaxQuadrics = 1 + ProjectedFreeForm::kMaxClipsSolved;
HWY_INLINE VD QuadricZeros(DD d, size_t quadrics, const double* squared, const VD* bs, const VD* cs,
                           double zlo, VD end) {
  const VD zero = hn::Zero(d), start = hn::Set(d, zlo);
  const auto value = [&](size_t j, VD z) {
    return hn::Add(hn::Mul(hn::Add(hn::Mul(hn::Set(d, squared[j]), z), bs[j]), z), cs[j]);
  };
  const auto inSpan = [&](VD z) { return hn::And(hn::Gt(z, start), hn::Le(z, end)); };
  // Inside at zlo (H, the least of the quadrics, ≥ 0): the crossing is the first exit from any
  // of them; outside, the first entry into one where all the others are inside.
  VD h = value(0, start);
  for (size_t j = 1; j < quadrics; ++j) h = hn::Min(h, value(j, start));
  const MD startInside = hn::Ge(h, zero);
  VD first = hn::Set(d, std::numeric_limits<double>::infinity());
  for (size_t j = 0; j < quadrics; ++j) {
    const VD b = bs[j], c = cs[j];
    // The stable quadratic formula: t = −(b + sign(b)·√D)/2, the roots t/a and c/t. The entry
    // (where the quadric turns positive, its slope +√D) is (−b + √D)/(2a), the exit
    // (−b − √D)/(2a): c/t and t/a where b ≥ 0, the other way round where b < 0. With a = 0,
    // c/t = −c/b is the one root and t/a is ±∞ or NaN, never in the span. D ≤ 0: no sign
    // change (a tangent touch is none).
    const VD disc = hn::Sub(hn::Mul(b, b), hn::Mul(hn::Set(d, 4 * squared[j]), c));
    const MD real = hn::Gt(disc, zero);
    const VD root = hn::CopySign(hn::Sqrt(hn::Max(disc, zero)), b);
    const VD t = hn::Mul(hn::Set(d, -0.5), hn::Add(b, root));
    const VD r1 = hn::Div(t, hn::Set(d, squared[j])), r2 = hn::Div(c, t);
    const MD nonNegative = hn::Ge(b, zero);
    const VD entry = hn::IfThenElse(nonNegative, r2, r1);
    const VD exit = hn::IfThenElse(nonNegative, r1, r2);
    MD entering = hn::AndNot(startInside, hn::And(real, inSpan(entry)));
    for (size_t i = 0; i < quadrics && !hn::AllFalse(d, entering); ++i)
      if (i != j) entering = hn::And(entering, hn::Ge(value(i, entry), zero));
    const MD exiting = hn::And(startInside, hn::And(real, inSpan(exit)));
    first = hn::IfThenElse(entering, hn::Min(first, entry), first);
    first = hn::IfThenElse(exiting, hn::Min(first, exit), first);
  }
  return hn::IfThenElse(hn::Le(first, end), first,
                        hn::Set(d, std::numeric_limits<double>::quiet_NaN()));
}

// The root's quadric and the clips (at most kMaxQuadrics in all), and their C.
struct QuadricList {
  const Quadric* q[kMaxQuadrics];
  double squared[kMaxQuadrics];
  size_t count;
  QuadricList(const ProjectedFreeForm::Node* nodes, const Quadric* clips, size_t clipCount)
      : count(std::min(1 + clipCount, kMaxQuadrics)) {
    for (size_t j = 0; j < count; ++j) {
      q[j] = j == 0 ? &nodes[0].q : &clips[j - 1];
      squared[j] = q[j]->c[2];
    }
  }
  // The first crossings along the lanes' rays (vx, vy) in (zlo, end] (QuadricZeros), the
  // quadrics' b and c held in registers.
  VD zeros(DD d, VD vx, VD vy, double zlo, VD end) const {
    VD b[kMaxQuadrics], c[kMaxQuadrics];
    for (size_t j = 0; j < count; ++j) AlongZ(d, *q[j], vx, vy, b[j], c[j]);
    return QuadricZeros(d, count, squared, b, c, zlo, end);
  }
};

void QuadricCrossings(const ProjectedFreeForm::Node* nodes, const Quadric* clips, size_t clipCount,
                      const double* x, const double* y, double zlo, const double* zhi, int count,
                      double* out) {
  const DD d;
  const QuadricList quadrics(nodes, clips, clipCount);
  ForEachVector(d, x, y, zlo, zhi, count, [&](size_t s0, size_t m, VD vx, VD vy, VD end) {
    StoreFirst(d, quadrics.zeros(d, vx, vy, zlo, end), m, out + s0);
  });
}

// A row of 8 pixels is a whole number of vectors on every target.
static_assert(HWY_LANES(double) <= 8 && 8 % HWY_LANES(double) == 0);

int QuadricHits(const ProjectedFreeForm::Node* nodes, const Quadric* clips, size_t clipCount,
                const double* columns, const double* rows, double zlo, double zhi,
                const HitRows& to, double* last) {
  const DD d;
  const hn::Rebind<float, DD> df;
  const hn::Rebind<uint32_t, DD> du;
  const hn::RebindToUnsigned<DD> d64;
  const size_t n = hn::Lanes(d);
  const QuadricList quadrics(nodes, clips, clipCount);
  const VD one = hn::Set(d, 1.0), half = hn::Set(d, 0.5);
  int hits = 0;
  for (size_t r = 0; r < 8; ++r) {
    const VD vy = hn::Set(d, rows[r]);
    float* const depth = to.depth + r * to.stride;
    float* const node = to.node + r * to.nodeStride;
    for (size_t c = 0; c < 8; c += n) {
      // The span ends at the depth the pixel holds, if nearer (Caster::windowRays).
      const auto held = hn::LoadU(df, depth + c);
      const VD end =
          hn::Min(hn::Set(d, zhi), hn::Sub(hn::Mul(hn::Set(d, 2.0), hn::PromoteTo(d, held)), one));
      const VD z = quadrics.zeros(d, hn::LoadU(d, columns + c), vy, zlo, end);
      // takeHit (raycast.cpp): the window depth, rounded to float, where nearer (never a NaN's).
      const auto nearer = hn::DemoteTo(df, hn::Mul(half, hn::Add(z, one)));
      const auto taken = hn::Lt(nearer, held);
      if (hn::AllFalse(df, taken)) continue;
      const MD takenD =
          hn::Gt(hn::PromoteTo(d, hn::IfThenElseZero(taken, hn::Set(df, 1.0f))), hn::Zero(d));
      // The cell is whole and its rows are the caster's own (Caster::quadricCell): storeWhere may
      // write every lane back.
      storeWhere(nearer, taken, df, depth + c);
      storeWhere(nearer, taken, df, node + c);
      if (to.object)
        storeWhere(hn::Set(du, to.id), hn::RebindMask(du, taken), du,
                   to.object + r * to.stride + c);
      if (to.cubeZ) storeWhere(z, takenD, d, to.cubeZ + r * to.stride + c);
      if (to.active)
        storeWhere(hn::Set(d64, to.activeBits), hn::RebindMask(d64, takenD), d64,
                   to.active + r * to.stride + c);
      hits += int(hn::CountTrue(d, takenD));
      // The last one taken, in raster order: the highest lane of this vector.
      uint8_t bits[8] = {};
      hn::StoreMaskBits(d, takenD, bits);
      int lane = 0;
      for (size_t i = 0; i < n; ++i)
        if (bits[i / 8] >> (i % 8) & 1) lane = int(i);
      alignas(64) double zs[8];
      hn::Store(z, d, zs);
      *last = zs[lane];
    }
  }
  return hits;
}

int ProvenCrossings(const ProjectedFreeForm::Node* nodes, const Quadric* clips, size_t clipCount,
                    const double* w, const double* x, const double* y, double zlo,
                    const double* zhi, int count, const double* guess, double* out,
                    uint64_t active) {
  const DD d;
  const size_t stride = 2 * (nodes[0].end + clipCount) * hn::Lanes(d);
  double* coefficients = CoefficientStorage(kGroup * stride);
  int bounds = 0;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  ForEachGroup(
      d, nodes, clips, clipCount, w, active, x, y, zlo, zhi, count, coefficients, stride,
      [&](const size_t* s0, const size_t* m, const Rays* rays, const VD* vz) {
        const VD a = hn::Set(d, zlo);
        VD g[kGroup], found[kGroup];
        MD span[kGroup], settled[kGroup];
        for (int k = 0; k < kGroup; ++k) {
          g[k] = LoadPadded(d, guess, s0[k], m[k], nan);
          span[k] = hn::Lt(a, vz[k]);
        }
        NewtonFromGuesses(d, rays, a, vz, g, span, found, settled);
        for (int k = 0; k < kGroup && m[k] > 0; ++k) {
          if (!hn::AllFalse(d, settled[k])) {
            // The proof: H monotonic over [zlo, zero] — no zero before this one.
            bounds += int(hn::CountTrue(d, settled[k]));
            Lanes value, slope;
            const MD valid =
                BoundLanes(d, rays[k], {a, hn::IfThenElse(settled[k], found[k], a)}, value, slope);
            settled[k] = hn::And(settled[k], hn::AndNot(ContainsZero(d, slope), valid));
          }
          StoreFirst(d, hn::IfThenElse(settled[k], found[k], hn::Set(d, nan)), m[k], out + s0[k]);
        }
      });
  return bounds;
}

int PiecewiseCrossings(const ProjectedFreeForm::Node* nodes, const Quadric* clips, size_t clipCount,
                       const double* w, const double* x, const double* y, double zlo,
                       const double* zhi, int count, int pieces, const double* guess, double* out,
                       double* from, uint64_t active) {
  const DD d;
  double* coefficients = CoefficientStorage(2 * (nodes[0].end + clipCount) * hn::Lanes(d));
  // The pieces divide [zlo, the farthest span end] of all the rays, whatever the lane count.
  double zMax = zlo;
  for (int i = 0; i < count; ++i) zMax = std::max(zMax, zhi[i]);
  int bounds = 0;
  ForEachVector(d, x, y, zlo, zhi, count, [&](size_t s0, size_t m, VD vx, VD vy, VD vz) {
    const Rays rays = SetUpRays(d, nodes, clips, clipCount, w, active, vx, vy, coefficients);
    const VD zero = hn::Zero(d), nan = hn::Set(d, std::numeric_limits<double>::quiet_NaN());
    VD found = nan, next = nan;
    MD pending = hn::Lt(hn::Set(d, zlo), vz);
    for (int k = 0; k < pieces && !hn::AllFalse(d, pending); ++k) {
      const double zA = zlo + (zMax - zlo) * k / pieces;
      const double zB = k + 1 == pieces ? zMax : zlo + (zMax - zlo) * (k + 1) / pieces;
      const VD a = hn::Set(d, zA), b = hn::Min(hn::Set(d, zB), vz);
      pending = hn::And(pending, hn::Lt(a, b));  // spans that end before the piece: no crossing
      bounds += int(hn::CountTrue(d, pending));
      Lanes value, slope;
      const MD valid = BoundLanes(d, rays, {a, b}, value, slope);
      const MD holds = hn::And(pending, hn::Or(hn::Not(valid), ContainsZero(d, value)));
      const MD monotonic = hn::AndNot(ContainsZero(d, slope), hn::And(holds, valid));
      // H may turn in the piece: the ray's own subdivision goes on from here (the caller's).
      const MD turns = hn::AndNot(monotonic, holds);
      next = hn::IfThenElse(turns, a, next);
      pending = hn::AndNot(turns, pending);
      if (hn::AllFalse(d, monotonic)) continue;
      // Monotonic: the ends decide.
      VD s;
      const VD fa = Evaluate(d, rays, a, s), fb = Evaluate(d, rays, b, s);
      const MD crossing = hn::And(monotonic, hn::Xor(hn::Ge(fa, zero), hn::Ge(fb, zero)));
      if (hn::AllFalse(d, crossing)) continue;
      found = hn::IfThenElse(
          crossing, Refine(d, rays, a, b, fa, fb, crossing, LoadPadded(d, guess, s0, m, 0)), found);
      pending = hn::AndNot(crossing, pending);
    }
    StoreFirst(d, found, m, out + s0);
    StoreFirst(d, next, m, from + s0);
  });
  return bounds;
}

// ProjectedFreeForm::crossingBracket: one ray's spans split into kFan pieces at a time, the
// pieces bounded together (a piece per lane; kFan / lanes vectors), depth first, front to back.
bool CrossingBracket(const ProjectedFreeForm::Node* nodes, const Quadric* clips, size_t clipCount,
                     const double* w, double x, double y, double zlo, double zhi, uint64_t active,
                     double narrowest, int budget, double* bracket, int* bounds) {
  constexpr int kFan = 8, kDepth = 24;
  const DD d;
  const size_t n = hn::Lanes(d);
  static_assert(HWY_LANES(double) <= kFan && kFan % HWY_LANES(double) == 0);
  double* coefficients = CoefficientStorage(2 * (nodes[0].end + clipCount) * n);
  const Rays rays =
      SetUpRays(d, nodes, clips, clipCount, w, active, hn::Set(d, x), hn::Set(d, y), coefficients);
  // A span [a, b] being taken: its pieces' ends z[0 … kFan], those that may hold a zero and
  // those where H is monotonic (bit k: piece k), the next piece to take, H at the ends (once
  // needed).
  struct Span {
    double z[kFan + 1];
    uint32_t holds, monotonic;
    int next;
    bool valued;
    double f[kFan + 1];
  };
  Span stack[kDepth];
  int depth = 0;
  const auto open = [&](double a, double b) {
    Span& s = stack[depth++];
    for (int k = 0; k < kFan; ++k) s.z[k] = a + (b - a) * k / kFan;
    s.z[kFan] = b;
    s.holds = s.monotonic = 0;
    s.next = 0;
    s.valued = false;
    for (size_t k0 = 0; k0 < size_t(kFan); k0 += n) {
      Lanes value, slope;
      const MD valid =
          BoundLanes(d, rays, {hn::LoadU(d, s.z + k0), hn::LoadU(d, s.z + k0 + 1)}, value, slope);
      const MD holds = hn::Or(hn::Not(valid), ContainsZero(d, value));
      const MD monotonic = hn::AndNot(ContainsZero(d, slope), hn::And(holds, valid));
      uint8_t bits[2][8] = {};
      hn::StoreMaskBits(d, holds, bits[0]);
      hn::StoreMaskBits(d, monotonic, bits[1]);
      for (size_t i = 0; i < n; ++i) {
        s.holds |= uint32_t(bits[0][i / 8] >> (i % 8) & 1) << (k0 + i);
        s.monotonic |= uint32_t(bits[1][i / 8] >> (i % 8) & 1) << (k0 + i);
      }
    }
    *bounds += kFan;
    --budget;
  };
  open(zlo, zhi);
  while (depth > 0) {
    Span& s = stack[depth - 1];
    while (s.next < kFan && !(s.holds >> s.next & 1)) ++s.next;
    if (s.next == kFan) {
      --depth;
      continue;
    }
    const int k = s.next++;
    const double a = s.z[k], b = s.z[k + 1];
    if ((s.monotonic >> k & 1) || b - a <= narrowest || depth == kDepth) {
      // One zero at most (or a bracket too narrow to split): the signs at the ends decide.
      if (!s.valued) {
        for (size_t k0 = 0; k0 <= size_t(kFan); k0 += n) {
          VD slope;
          const VD f =
              Evaluate(d, rays, LoadPadded(d, s.z, k0, std::min(n, kFan + 1 - k0), b), slope);
          StoreFirst(d, f, std::min(n, kFan + 1 - k0), s.f + k0);
        }
        s.valued = true;
      }
      if ((s.f[k] >= 0) == (s.f[k + 1] >= 0)) continue;
      bracket[0] = a, bracket[1] = b, bracket[2] = s.f[k], bracket[3] = s.f[k + 1];
      return true;
    }
    if (budget == 0) return false;
    open(a, b);
  }
  return false;
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::freeform
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sv::freeform {

HWY_EXPORT(MonotonicCrossings);
HWY_EXPORT(PiecewiseCrossings);
HWY_EXPORT(ProvenCrossings);
HWY_EXPORT(QuadricCrossings);
HWY_EXPORT(QuadricHits);
HWY_EXPORT(CrossingBracket);

void ProjectedFreeForm::monotonicCrossings(const double* x, const double* y, double zlo,
                                           const double* zhi, int count, const double* guess,
                                           double* z, uint64_t active) const {
  HWY_DYNAMIC_DISPATCH(MonotonicCrossings)
  (nodes_.data(), clips_.data(), clips_.size(), inverse_.m[3].data(), x, y, zlo, zhi,
   std::clamp(count, 0, 16), guess, z, active);
}

void ProjectedFreeForm::quadricCrossings(const double* x, const double* y, double zlo,
                                         const double* zhi, int count, double* z) const {
  HWY_DYNAMIC_DISPATCH(QuadricCrossings)
  (nodes_.data(), clips_.data(), clips_.size(), x, y, zlo, zhi, std::max(count, 0), z);
}

int ProjectedFreeForm::quadricHits(const double* columns, const double* rows, double zlo,
                                   double zhi, const HitRows& to, double& last) const {
  return HWY_DYNAMIC_DISPATCH(QuadricHits)(nodes_.data(), clips_.data(), clips_.size(), columns,
                                           rows, zlo, zhi, to, &last);
}

bool ProjectedFreeForm::crossingBracket(double x, double y, double zlo, double zhi, uint64_t active,
                                        double narrowest, int budget, double bracket[4],
                                        int& bounds) const {
  return HWY_DYNAMIC_DISPATCH(CrossingBracket)(nodes_.data(), clips_.data(), clips_.size(),
                                               inverse_.m[3].data(), x, y, zlo, zhi, active,
                                               narrowest, budget, bracket, &bounds);
}

int ProjectedFreeForm::provenCrossings(const double* x, const double* y, double zlo,
                                       const double* zhi, int count, const double* guess, double* z,
                                       uint64_t active) const {
  return HWY_DYNAMIC_DISPATCH(ProvenCrossings)(nodes_.data(), clips_.data(), clips_.size(),
                                               inverse_.m[3].data(), x, y, zlo, zhi,
                                               std::clamp(count, 0, 16), guess, z, active);
}

int ProjectedFreeForm::piecewiseCrossings(const double* x, const double* y, double zlo,
                                          const double* zhi, int count, int pieces,
                                          const double* guess, double* z, double* from,
                                          uint64_t active) const {
  return HWY_DYNAMIC_DISPATCH(PiecewiseCrossings)(
      nodes_.data(), clips_.data(), clips_.size(), inverse_.m[3].data(), x, y, zlo, zhi,
      std::clamp(count, 0, 16), std::max(pieces, 1), guess, z, from, active);
}

}  // namespace sv::freeform
#endif  // HWY_ONCE
