// Based on: SPEC §12 (the finest level: the ray against the interpolated surface), §11.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "terrain/packet_walk.cpp"
// clang-format off: foreach_target.h first
#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"
// clang-format on

#include <algorithm>
#include <limits>

#include "terrain/packet_walk.h"
#include "terrain/pyramid.h"

HWY_BEFORE_NAMESPACE();
namespace sv::terrain {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// A vector of lanes' rays (packet_walk.h: x = x0 + t·ex, …) and a cell's corner codes.
template <class DF>
struct CellRays {
  hn::Vec<DF> x0, y0, z0, ex, ey, ez;
};
template <class DF>
struct Corners {
  hn::Vec<DF> h00, h10, h01, h11;
};

// The lanes of `near` whose ray meets the cell's bilinear surface between t and out (the cell's
// corner at (fi, fj) from the anchor): their first crossing into `hit`, the mask returned.
template <class DF>
hn::Mask<DF> SolveCell(DF df, const CellRays<DF>& r, hn::Mask<DF> near, hn::Vec<DF> t,
                       hn::Vec<DF> out, hn::Vec<DF> fi, hn::Vec<DF> fj, const Corners<DF>& h,
                       hn::Vec<DF>& hit) {
  using VF = hn::Vec<DF>;
  const VF zero = hn::Zero(df), half = hn::Set(df, 0.5f);
  const VF inf = hn::Set(df, std::numeric_limits<float>::infinity());
  if (hn::AllFalse(df, near)) return near;
  // h = h00 + b·u + c·v + g·u·v, u = x − i, v = y − j; along the ray from t, z − h =
  // f(τ) = A·τ² + B·τ + C. Whether f has a root in [0, span] needs no division: f(0) = C > 0
  // (else the ray is below the surface at t already: met there); a root iff f(span) ≤ 0, or f is
  // convex (A > 0) with its vertex −B/2A inside the span and a real root (disc ≥ 0).
  const VF b = hn::Sub(h.h10, h.h00), c = hn::Sub(h.h01, h.h00);
  const VF gg = hn::Add(hn::Sub(hn::Sub(h.h11, h.h10), h.h01), h.h00);
  const VF u0 = hn::Sub(hn::Add(r.x0, hn::Mul(t, r.ex)), fi);
  const VF v0 = hn::Sub(hn::Add(r.y0, hn::Mul(t, r.ey)), fj);
  const VF A = hn::Neg(hn::Mul(hn::Mul(gg, r.ex), r.ey));
  const VF B = hn::Sub(hn::Sub(hn::Sub(r.ez, hn::Mul(b, r.ex)), hn::Mul(c, r.ey)),
                       hn::Mul(gg, hn::Add(hn::Mul(u0, r.ey), hn::Mul(v0, r.ex))));
  const VF surface = hn::Add(hn::Add(hn::Add(h.h00, hn::Mul(b, u0)), hn::Mul(c, v0)),
                             hn::Mul(hn::Mul(gg, u0), v0));
  const VF C = hn::Sub(hn::Add(r.z0, hn::Mul(t, r.ez)), surface);
  const VF span = hn::Sub(out, t);
  const VF atEnd = hn::Add(hn::Mul(hn::Add(hn::Mul(A, span), B), span), C);
  const VF disc = hn::Sub(hn::Mul(B, B), hn::Mul(hn::Mul(hn::Set(df, 4.0f), A), C));
  const auto under = hn::Le(C, zero);
  const auto vertexInside = hn::And(hn::And(hn::Gt(A, zero), hn::Lt(B, zero)),
                                    hn::Lt(hn::Neg(B), hn::Mul(hn::Add(A, A), span)));
  const auto met = hn::And(
      near, hn::Or(hn::Or(under, hn::Le(atEnd, zero)), hn::And(vertexInside, hn::Ge(disc, zero))));
  if (hn::AllFalse(df, met)) return met;
  // The first root: of the stable pair q/A and C/q (q = −(B + sign(B)·√disc)/2), the smaller
  // non-negative one (A = 0 makes q/A infinite and C/q = −C/B), within the span.
  const VF q = hn::Neg(hn::Mul(half, hn::Add(B, hn::CopySign(hn::Sqrt(hn::Max(disc, zero)), B))));
  const VF rootA = hn::Div(q, A);
  const VF rootB = hn::IfThenElse(hn::Eq(q, zero), inf, hn::Div(C, q));
  const VF firstA = hn::IfThenElse(hn::Ge(rootA, zero), rootA, inf);
  const VF firstB = hn::IfThenElse(hn::Ge(rootB, zero), rootB, inf);
  const VF root = hn::IfThenElse(under, zero, hn::Min(hn::Min(firstA, firstB), span));
  hit = hn::IfThenElse(met, hn::Add(t, root), hit);
  return met;
}

// The lanes' spans [t, t1] clipped to the footprint [footX0, footX1] × [footY0, footY1] (slabs):
// beyond it there is no surface, and where a ray enters it below the heights it meets the prism's
// wall. The lanes left with a span.
template <class DF>
hn::Mask<DF> ClipToFootprint(DF df, const PacketGrid& g, hn::Vec<DF> x0, hn::Vec<DF> y0,
                             hn::Vec<DF> ex, hn::Vec<DF> ey, hn::Vec<DF>& t, hn::Vec<DF>& t1) {
  using VF = hn::Vec<DF>;
  auto active = hn::Le(t, t1);
  auto clip = [&](VF p0, VF e, float lo, float hi) {
    const auto flat = hn::Eq(e, hn::Zero(df));
    const VF a = hn::Div(hn::Sub(hn::Set(df, lo), p0), e),
             b = hn::Div(hn::Sub(hn::Set(df, hi), p0), e);
    const auto outside = hn::Or(hn::Lt(p0, hn::Set(df, lo)), hn::Gt(p0, hn::Set(df, hi)));
    active = hn::AndNot(hn::And(flat, outside), active);
    t = hn::IfThenElse(flat, t, hn::Max(t, hn::Min(a, b)));
    t1 = hn::IfThenElse(flat, t1, hn::Min(t1, hn::Max(a, b)));
  };
  clip(x0, ex, g.footX0, g.footX1);
  clip(y0, ey, g.footY0, g.footY1);
  return hn::And(active, hn::Le(t, t1));
}

// The two 16-bit codes a 32-bit read holds: the first (low) and the second (high).
template <class DI>
hn::Vec<DI> Low16(DI di, hn::Vec<DI> r) {
  return hn::And(r, hn::Set(di, 0xFFFF));
}
template <class DI>
hn::Vec<DI> High16(DI di, hn::Vec<DI> r) {
  const hn::RebindToUnsigned<DI> du;
  return hn::BitCast(di, hn::ShiftRight<16>(hn::BitCast(du, r)));
}

// The lanes of `lanes` (their cells (ci, cj) from the anchor, spans [t, out] in them) against the
// table's Catmull–Rom patch over the cell — Caster::solveBicubicCell's rule in float: the height
// above the patch sampled at eighths of a cell along the ray, the first bracket refined by regula
// falsi with the Illinois step to 10⁻⁴ of a cell. Their first crossing into `hit`, the mask
// returned. Heights are taken relative to the cell's own sample (the patch's p11), so float keeps
// the relief's detail however high the table's codes are.
template <class DF, class VI>
hn::Mask<DF> SolvePatches(DF df, const PacketGrid& g, const CellRays<DF>& r, hn::Mask<DF> lanes,
                          VI ci, VI cj, hn::Vec<DF> t, hn::Vec<DF> out, hn::Vec<DF>& hit) {
  const hn::RebindToSigned<DF> di;
  using VF = hn::Vec<DF>;
  const VF zero = hn::Zero(df), half = hn::Set(df, 0.5f);
  // The 4×4 samples around the cell, edges repeated (cellSamples): per row two 32-bit reads of two
  // codes each, at columns (i − 1, i) and (i + 1, i + 2) moved inside the row at its ends.
  const VI i = hn::Add(ci, hn::Set(di, g.anchorI)), j = hn::Add(cj, hn::Set(di, g.anchorJ));
  const VI colA = hn::Max(hn::Sub(i, hn::Set(di, 1)), hn::Zero(di));
  const VI colB = hn::Min(hn::Add(i, hn::Set(di, 1)), hn::Set(di, g.cellsX - 1));
  const auto firstColumn = hn::Eq(i, hn::Zero(di)),
             lastColumn = hn::Eq(i, hn::Set(di, g.cellsX - 1));
  const int32_t* table = reinterpret_cast<const int32_t*>(g.q);
  VI codes[4][4];
  for (int y = 0; y < 4; ++y) {
    const VI row =
        hn::Min(hn::Max(hn::Add(j, hn::Set(di, y - 1)), hn::Zero(di)), hn::Set(di, g.cellsY));
    const VI start = hn::Mul(row, hn::Set(di, g.width));
    const VI a = hn::GatherOffset(di, table, hn::ShiftLeft<1>(hn::Add(start, colA)));
    const VI b = hn::GatherOffset(di, table, hn::ShiftLeft<1>(hn::Add(start, colB)));
    const VI lowA = Low16(di, a), lowB = Low16(di, b);
    const VI highA = High16(di, a), highB = High16(di, b);
    codes[y][0] = lowA;
    codes[y][1] = hn::IfThenElse(firstColumn, lowA, highA);
    codes[y][2] = hn::IfThenElse(lastColumn, highB, lowB);
    codes[y][3] = highB;
  }
  // The patch as a polynomial P(u, v) = Σ a[l][k]·u^k·v^l (caster.cpp's kBasis, written out),
  // relative to its own sample p11.
  auto basis = [&](const VF p[4], VF c[4]) {
    c[0] = p[1];
    c[1] = hn::Mul(half, hn::Sub(p[2], p[0]));
    c[2] = hn::Sub(hn::Add(p[0], hn::Add(p[2], p[2])),
                   hn::Add(hn::Mul(hn::Set(df, 2.5f), p[1]), hn::Mul(half, p[3])));
    c[3] = hn::Add(hn::Mul(hn::Set(df, 1.5f), hn::Sub(p[1], p[2])),
                   hn::Mul(half, hn::Sub(p[3], p[0])));
  };
  VF rows[4][4];
  for (int y = 0; y < 4; ++y) {
    VF h[4];
    for (int x = 0; x < 4; ++x) h[x] = hn::ConvertTo(df, hn::Sub(codes[y][x], codes[1][1]));
    basis(h, rows[y]);
  }
  VF a[4][4];  // a[l][k]
  for (int k = 0; k < 4; ++k) {
    const VF column[4] = {rows[0][k], rows[1][k], rows[2][k], rows[3][k]};
    VF c[4];
    basis(column, c);
    for (int l = 0; l < 4; ++l) a[l][k] = c[l];
  }
  // Along the ray from t (τ = t' − t): u = u0 + τ·ex, v = v0 + τ·ey, and the height above the
  // patch f(τ) = z0' + τ·ez − P(u, v), a polynomial of degree 6 in τ composed once (as
  // solveBicubicCell does), each evaluation Estrin's scheme (five operations deep where Horner's
  // rule is twelve: the refinement's steps wait on it).
  const VF u0 = hn::Sub(hn::Add(r.x0, hn::Mul(t, r.ex)), hn::ConvertTo(df, ci));
  const VF v0 = hn::Sub(hn::Add(r.y0, hn::Mul(t, r.ey)), hn::ConvertTo(df, cj));
  VF U[4][4], V[4][4];  // U[k][c]: the coefficient of τ^c in (u0 + τ·ex)^k
  for (int k = 0; k < 4; ++k)
    for (int c = 0; c < 4; ++c) U[k][c] = V[k][c] = zero;
  U[0][0] = V[0][0] = hn::Set(df, 1.0f);
  for (int k = 1; k < 4; ++k)
    for (int c = 0; c <= k; ++c) {
      U[k][c] = hn::Add(c < k ? hn::Mul(U[k - 1][c], u0) : zero,
                        c > 0 ? hn::Mul(U[k - 1][c - 1], r.ex) : zero);
      V[k][c] = hn::Add(c < k ? hn::Mul(V[k - 1][c], v0) : zero,
                        c > 0 ? hn::Mul(V[k - 1][c - 1], r.ey) : zero);
    }
  VF f[7];
  f[0] = hn::Sub(hn::Add(r.z0, hn::Mul(t, r.ez)),
                 hn::Sub(hn::ConvertTo(df, codes[1][1]), hn::Set(df, g.anchorZ)));
  f[1] = r.ez;
  for (int c = 2; c < 7; ++c) f[c] = zero;
  for (int l = 0; l < 4; ++l) {
    VF q[4];  // Σ_k a[l][k]·U[k]
    for (int c = 0; c < 4; ++c) {
      q[c] = zero;
      for (int k = c; k < 4; ++k) q[c] = hn::Add(q[c], hn::Mul(a[l][k], U[k][c]));
    }
    for (int c = 0; c <= l; ++c)
      for (int e = 0; e < 4; ++e) f[c + e] = hn::Sub(f[c + e], hn::Mul(V[l][c], q[e]));
  }
  auto above = [&](VF tau) {
    const VF tau2 = hn::Mul(tau, tau), tau4 = hn::Mul(tau2, tau2);
    const VF low = hn::Add(f[0], hn::Mul(f[1], tau)), mid = hn::Add(f[2], hn::Mul(f[3], tau));
    const VF high = hn::Add(hn::Add(f[4], hn::Mul(f[5], tau)), hn::Mul(f[6], tau2));
    return hn::Add(hn::Add(low, hn::Mul(mid, tau2)), hn::Mul(high, tau4));
  };
  const VF span = hn::Max(hn::Sub(out, t), zero);
  const VF speed = hn::Sqrt(hn::Add(hn::Mul(r.ex, r.ex), hn::Mul(r.ey, r.ey)));  // cells a unit t
  const VF f0 = above(zero);
  const auto under = hn::And(lanes, hn::Le(f0, zero));
  // Samples an eighth of a cell apart: n = ⌈8·span·speed⌉ (1 … 12 in a cell).
  const VF n = hn::Min(
      hn::Max(hn::Ceil(hn::Mul(hn::Mul(hn::Set(df, 8.0f), span), speed)), hn::Set(df, 1.0f)),
      hn::Set(df, 64.0f));
  VF lo = zero, fLo = f0, hi = span, fHi = f0;
  auto searching = hn::AndNot(under, lanes), found = hn::And(under, hn::Not(under));
  // Four samples at a time: their evaluations are independent chains the core overlaps.
  constexpr int kBatch = 4;
  VF s0 = zero, fs0 = f0;
  for (int k = 1; !hn::AllFalse(df, searching); k += kBatch) {
    VF s[kBatch], fs[kBatch];
    for (int b = 0; b < kBatch; ++b) {
      const VF kf = hn::Set(df, float(k + b));
      s[b] = hn::IfThenElse(hn::Ge(kf, n), span, hn::Div(hn::Mul(span, kf), n));
      fs[b] = above(s[b]);
    }
    for (int b = 0; b < kBatch; ++b) {
      const auto last = hn::Ge(hn::Set(df, float(k + b)), n);
      const auto crossed = hn::And(searching, hn::Le(fs[b], zero));
      lo = hn::IfThenElse(crossed, s0, lo), fLo = hn::IfThenElse(crossed, fs0, fLo);
      hi = hn::IfThenElse(crossed, s[b], hi), fHi = hn::IfThenElse(crossed, fs[b], fHi);
      found = hn::Or(found, crossed);
      searching = hn::AndNot(hn::Or(crossed, last), searching);
      s0 = s[b], fs0 = fs[b];
    }
  }
  // The bracket [lo, hi], f(lo) > 0 ≥ f(hi), narrowed as refineRoot does (caster.cpp).
  const VF tolerance = hn::Div(hn::Set(df, 1e-4f), hn::Max(speed, hn::Set(df, 1e-30f)));
  VF side = zero;  // −1: the last step moved hi, +1: lo
  auto refining = hn::And(found, hn::Gt(hn::Sub(hi, lo), tolerance));
  for (int it = 0; it < 60 && !hn::AllFalse(df, refining); ++it) {
    const VF secant = hn::Sub(hi, hn::Div(hn::Mul(fHi, hn::Sub(hi, lo)), hn::Sub(fHi, fLo)));
    const VF middle = hn::Mul(half, hn::Add(lo, hi));
    const auto inside =
        hn::And(hn::Gt(hn::Sub(fLo, fHi), zero), hn::And(hn::Gt(secant, lo), hn::Lt(secant, hi)));
    const VF m = hn::IfThenElse(inside, secant, middle);
    const VF fm = above(m);
    const auto toHi = hn::And(refining, hn::Le(fm, zero));
    const auto toLo = hn::AndNot(toHi, refining);
    const VF minus = hn::Set(df, -1.0f), plus = hn::Set(df, 1.0f);
    fLo = hn::IfThenElse(hn::And(toHi, hn::Eq(side, minus)), hn::Mul(half, fLo), fLo);
    fHi = hn::IfThenElse(hn::And(toLo, hn::Eq(side, plus)), hn::Mul(half, fHi), fHi);
    hi = hn::IfThenElse(toHi, m, hi), fHi = hn::IfThenElse(toHi, fm, fHi);
    lo = hn::IfThenElse(toLo, m, lo), fLo = hn::IfThenElse(toLo, fm, fLo);
    side = hn::IfThenElse(toHi, minus, hn::IfThenElse(toLo, plus, side));
    refining = hn::And(refining, hn::Gt(hn::Sub(hi, lo), tolerance));
  }
  hit = hn::IfThenElse(under, t, hn::IfThenElse(found, hn::Add(t, hi), hit));
  return hn::Or(under, found);
}

// Along an axis the lane crosses: the next cell — past its square's edge for a lane that passed
// the square (`skip`), else the cell beside.
template <class DI, class MI, class MF>
hn::Vec<DI> Across(DI di, MI skip, MF positive, hn::Vec<DI> square, hn::Vec<DI> cell,
                   hn::Vec<DI> step) {
  const hn::Vec<DI> past =
      hn::IfThenElse(hn::RebindMask(di, positive), hn::Add(square, hn::Set(di, Pyramid::kTopCells)),
                     hn::Sub(square, hn::Set(di, 1)));
  return hn::IfThenElse(skip, past, hn::Add(cell, step));
}
// Along the axis it does not cross: its cell — for a lane that passed a square, the one of the
// square's where it leaves it (`p` its coordinate there), within the grid's [lo, hi].
template <class DI, class MI, class VF>
hn::Vec<DI> Within(DI di, MI skip, VF p, hn::Vec<DI> cell, hn::Vec<DI> square, hn::Vec<DI> lo,
                   hn::Vec<DI> hi) {
  const hn::Vec<DI> c = hn::ConvertTo(di, hn::Floor(p));
  const hn::Vec<DI> inSquare =
      hn::Min(hn::Max(c, square), hn::Add(square, hn::Set(di, Pyramid::kTopCells - 1)));
  return hn::Min(hn::Max(hn::IfThenElse(skip, inSquare, cell), lo), hi);
}

// Whether lo ≤ v ≤ hi, lane by lane.
template <class DI>
hn::Mask<DI> InRange(DI di, hn::Vec<DI> v, hn::Vec<DI> lo, hn::Vec<DI> hi) {
  return hn::And(hn::Gt(v, hn::Sub(lo, hn::Set(di, 1))), hn::Lt(v, hn::Add(hi, hn::Set(di, 1))));
}

// The step budget of a walk's lanes, each its own (a lane's walk never depends on its
// neighbours'): lanes out of steps are `spent`, their t where to go on from.
template <class DF>
struct StepBudget {
  using VI = hn::Vec<hn::RebindToSigned<DF>>;
  StepBudget(DF df, int maxCells)
      : taken(hn::Zero(hn::RebindToSigned<DF>())),
        cells(hn::Set(hn::RebindToSigned<DF>(), maxCells)),
        spent(hn::Lt(hn::Zero(df), hn::Zero(df))) {}
  // The active lanes that have taken their steps: spent.
  void spend(DF df, hn::Mask<DF>& active) {
    const auto out = hn::AndNot(hn::RebindMask(df, hn::Lt(taken, cells)), active);
    spent = hn::Or(spent, out);
    active = hn::AndNot(out, active);
  }
  void take(hn::Mask<DF> active) {
    const hn::RebindToSigned<DF> di;
    taken = hn::Add(taken, hn::IfThenElseZero(hn::RebindMask(di, active), hn::Set(di, 1)));
  }
  VI taken, cells;
  hn::Mask<DF> spent;
};

// Bicubic: lanes parked at the cell they may touch — its index (i, j) and their span [t, out]
// in it — to solve their patches in one pass (SolvePatches costs a few dozen steps' work: solved
// as each lane comes, it would run at nearly every step of a vector).
// `resume`: the parked lanes already moved on to their next cell, to go on from there if they
// miss the patch.
template <class DF>
struct Parked {
  using VF = hn::Vec<DF>;
  using VI = hn::Vec<hn::RebindToSigned<DF>>;
  Parked(DF df, VI ci, VI cj, VF t0)
      : lanes(hn::Lt(hn::Zero(df), hn::Zero(df))), resume(lanes), i(ci), j(cj), t(t0), out(t0) {}
  void park(hn::Mask<DF> met, hn::Mask<DF> moves, VI ci, VI cj, VF tIn, VF outIn) {
    const hn::RebindToSigned<DF> di;
    const auto metI = hn::RebindMask(di, met);
    i = hn::IfThenElse(metI, ci, i), j = hn::IfThenElse(metI, cj, j);
    t = hn::IfThenElse(met, tIn, t), out = hn::IfThenElse(met, outIn, out);
    lanes = hn::Or(lanes, met);
    resume = hn::Or(resume, hn::And(met, moves));
  }
  // Due when no lane walks: the lanes that have not met a patch yet walk on meanwhile, so each
  // pass solves as many as it can (the vector's lanes at most; measured against solving when half
  // or three quarters were parked: 4 % and 2 % faster).
  bool due(DF df, hn::Mask<DF> active) const {
    return !hn::AllFalse(df, lanes) && hn::AllFalse(df, active);
  }
  // Their patches solved (hits into `hit`); those that missed and have a next cell walk on.
  void solve(DF df, const PacketGrid& g, const CellRays<DF>& rays, hn::Mask<DF>& active, VF& hit) {
    const auto met = SolvePatches(df, g, rays, lanes, i, j, t, out, hit);
    active = hn::Or(active, hn::AndNot(met, resume));
    lanes = resume = hn::AndNot(lanes, lanes);
  }
  hn::Mask<DF> lanes, resume;
  VI i, j;
  VF t, out;
};

// One vector of lanes, from lane `first`: each lane's span clipped to the table's footprint, then
// walked until it is done or has taken maxCells steps — per lane Caster::solveBilinear's cells, in
// float, with the skip map's squares passed at once (SPEC §12: a node the ray stays above is
// skipped). Per step a lane is in one cell; where it has just entered a square, it first asks
// whether its ray stays above the square's top from there until it leaves the square: then the
// step takes it to the next square, else it solves the cell as any other.
template <bool kBicubic, class DF>
void WalkLanes(DF df, const PacketGrid& g, PacketLanes& L, size_t first, int maxCells) {
  const hn::RebindToSigned<DF> di;
  using VF = hn::Vec<DF>;
  using VI = hn::Vec<decltype(di)>;
  const VF zero = hn::Zero(df), one = hn::Set(df, 1.0f);
  const VF inf = hn::Set(df, std::numeric_limits<float>::infinity());
  const VF x0 = hn::Load(df, L.x0 + first), y0 = hn::Load(df, L.y0 + first);
  const VF z0 = hn::Load(df, L.z0 + first);
  const VF ex = hn::Load(df, L.ex + first), ey = hn::Load(df, L.ey + first);
  const VF ez = hn::Load(df, L.ez + first);
  VF t = hn::Load(df, L.t0 + first), t1 = hn::Load(df, L.t1 + first);
  const auto posX = hn::Gt(ex, zero), posY = hn::Gt(ey, zero);
  const auto flatX = hn::Eq(ex, zero), flatY = hn::Eq(ey, zero);
  auto active = ClipToFootprint(df, g, x0, y0, ex, ey, t, t1);
  t = hn::IfThenElseZero(active, t);  // idle lanes: at the anchor's cell (a valid sample index)
  // The cell holding the start (the last row and column belong to the cells before them),
  // relative to the anchor; and the range of cells, inclusive.
  const VI loI = hn::Set(di, -g.anchorI), hiI = hn::Set(di, g.cellsX - 1 - g.anchorI);
  const VI loJ = hn::Set(di, -g.anchorJ), hiJ = hn::Set(di, g.cellsY - 1 - g.anchorJ);
  auto cellOf = [&](VF p, VI lo, VI hi) {
    const VI c = hn::ConvertTo(di, hn::Floor(hn::IfThenElseZero(active, p)));
    return hn::Min(hn::Max(c, lo), hi);
  };
  VI ci = cellOf(hn::Add(x0, hn::Mul(t, ex)), loI, hiI);
  VI cj = cellOf(hn::Add(y0, hn::Mul(t, ey)), loJ, hiJ);
  // Where the ray crosses x = X: (X − x0)/ex, as a product (flat axes: never).
  const VF invX = hn::IfThenElse(flatX, zero, hn::Div(one, ex));
  const VF invY = hn::IfThenElse(flatY, zero, hn::Div(one, ey));
  auto cross = [&](VF boundary, VF p0, VF inv, auto flat) {
    return hn::IfThenElse(flat, inf, hn::Mul(hn::Sub(boundary, p0), inv));
  };
  const VI stepI = hn::IfThenElse(hn::RebindMask(di, posX), hn::Set(di, 1), hn::Set(di, -1));
  const VI stepJ = hn::IfThenElse(hn::RebindMask(di, posY), hn::Set(di, 1), hn::Set(di, -1));
  const VI squareMask = hn::Set(di, ~(Pyramid::kTopCells - 1));  // a cell → its square's first
  const VF squareCells = hn::Set(df, float(Pyramid::kTopCells));
  // The cells' samples (bilinear), or their tops (bicubic: a row of cellsX).
  const int rowCells = kBicubic ? g.cellsX : g.width;
  const uint16_t* cells = kBicubic ? g.cellTop : g.q;
  const int32_t* base = reinterpret_cast<const int32_t*>(
      cells + size_t(g.anchorJ) * size_t(rowCells) + size_t(g.anchorI));
  const VI width = hn::Set(di, rowCells), topWidth = hn::Set(di, g.topWidth);
  const int32_t* topBase = reinterpret_cast<const int32_t*>(
      g.top + size_t(g.anchorJ / Pyramid::kTopCells) * size_t(g.topWidth) +
      size_t(g.anchorI / Pyramid::kTopCells));
  const VI row = hn::Set(di, 2 * g.width);  // bytes to the next row of samples
  const VF anchorZ = hn::Set(df, g.anchorZ);
  VF hit = hn::Set(df, std::numeric_limits<float>::quiet_NaN());
  // A cell's four samples: two 32-bit reads a row, each two adjacent 16-bit codes; its square's
  // top: one read. The next step's are read before this step's cell is solved (where a lane goes
  // next does not depend on whether it meets the surface here), so that the reads' latency
  // overlaps the solve.
  auto gather = [&](VI i, VI j, VI& r0, VI& r1, VI& top) {
    const VI offset = hn::ShiftLeft<1>(hn::Add(hn::Mul(j, width), i));
    r0 = hn::GatherOffset(di, base, offset);
    r1 = kBicubic ? r0 : hn::GatherOffset(di, base, hn::Add(offset, row));
    const VI square = hn::Add(hn::Mul(hn::ShiftRight<Pyramid::kTopShift>(j), topWidth),
                              hn::ShiftRight<Pyramid::kTopShift>(i));
    top = hn::GatherOffset(di, topBase, hn::ShiftLeft<1>(square));
  };
  auto code = [&](VI r) { return hn::Sub(hn::ConvertTo(df, Low16(di, r)), anchorZ); };
  auto codeHigh = [&](VI r) { return hn::Sub(hn::ConvertTo(df, High16(di, r)), anchorZ); };
  const VI noTop = hn::Set(di, Pyramid::kNoTop);
  auto bounded = [&](VI r) { return hn::RebindMask(df, hn::Lt(Low16(di, r), noTop)); };
  auto entered = active;  // lanes that have just entered a square
  StepBudget<DF> budget(df, maxCells);
  Parked<DF> parked(df, ci, cj, t);
  const CellRays<DF> rays{x0, y0, z0, ex, ey, ez};
  VI r0, r1, rTop;
  gather(ci, cj, r0, r1, rTop);
  for (;;) {
    budget.spend(df, active);
    if constexpr (kBicubic) {
      if (parked.due(df, active)) {
        parked.solve(df, g, rays, active, hit);
        budget.spend(df, active);
      }
    }
    if (hn::AllFalse(df, active)) break;
    budget.take(active);
    const VF fi = hn::ConvertTo(df, ci), fj = hn::ConvertTo(df, cj);
    const VI si = hn::And(ci, squareMask), sj = hn::And(cj, squareMask);
    const VF fsi = hn::ConvertTo(df, si), fsj = hn::ConvertTo(df, sj);
    // Where the ray leaves its cell and its square.
    const VF txCell = cross(hn::IfThenElse(posX, hn::Add(fi, one), fi), x0, invX, flatX);
    const VF tyCell = cross(hn::IfThenElse(posY, hn::Add(fj, one), fj), y0, invY, flatY);
    const VF txSquare =
        cross(hn::IfThenElse(posX, hn::Add(fsi, squareCells), fsi), x0, invX, flatX);
    const VF tySquare =
        cross(hn::IfThenElse(posY, hn::Add(fsj, squareCells), fsj), y0, invY, flatY);
    const VF outCell = hn::Max(hn::Min(hn::Min(txCell, tyCell), t1), t);
    const VF outSquare = hn::Max(hn::Min(hn::Min(txSquare, tySquare), t1), t);
    // The square passed: its top below the ray's lowest point in it from t on.
    const VF lowestInSquare =
        hn::Add(z0, hn::Mul(hn::IfThenElse(hn::Lt(ez, zero), outSquare, t), ez));
    const auto skip = hn::And(hn::And(hn::And(entered, active), bounded(rTop)),
                              hn::Gt(lowestInSquare, code(rTop)));
    // This step's end: the square's exit for the lanes that pass it, the cell's for the rest.
    const VF tx = hn::IfThenElse(skip, txSquare, txCell);
    const VF ty = hn::IfThenElse(skip, tySquare, tyCell);
    const VF out = hn::IfThenElse(skip, outSquare, outCell);
    // The next cell, for the lanes that go on unless this cell stops them: t1 reached, or the
    // grid left (Caster::solveBilinear's misses both); a lane that leaves keeps its last, valid
    // cell. Out of a square, the next square's cell where the ray enters it.
    const auto goOn = hn::AndNot(hn::Ge(out, t1), active);
    const auto alongX = hn::RebindMask(di, hn::Le(tx, ty));
    const auto skipI = hn::RebindMask(di, skip);
    const VF outFinite = hn::IfThenElse(hn::IsFinite(out), out, t);
    const VI nextI =
        hn::IfThenElse(alongX, Across(di, skipI, posX, si, ci, stepI),
                       Within(di, skipI, hn::Add(x0, hn::Mul(outFinite, ex)), ci, si, loI, hiI));
    const VI nextJ = hn::IfThenElse(
        alongX, Within(di, skipI, hn::Add(y0, hn::Mul(outFinite, ey)), cj, sj, loJ, hiJ),
        Across(di, skipI, posY, sj, cj, stepJ));
    const auto inside = hn::And(InRange(di, nextI, loI, hiI), InRange(di, nextJ, loJ, hiJ));
    const auto moves = hn::And(goOn, hn::RebindMask(df, inside));
    const auto movesI = hn::RebindMask(di, moves);
    const VI ni = hn::IfThenElse(movesI, nextI, ci), nj = hn::IfThenElse(movesI, nextJ, cj);
    VI n0, n1, nTop;
    gather(ni, nj, n0, n1, nTop);
    // This cell, for the lanes that did not pass its square: solved only where the ray's lowest
    // point in it is not above its highest corner — or, bicubic, parked where it is not above the
    // top of the cell's patch.
    const VF lowest = hn::Add(z0, hn::Mul(hn::IfThenElse(hn::Lt(ez, zero), outCell, t), ez));
    hn::Mask<DF> met;
    if constexpr (kBicubic) {
      met =
          hn::AndNot(skip, hn::And(active, hn::Or(hn::Not(bounded(r0)), hn::Le(lowest, code(r0)))));
      parked.park(met, moves, ci, cj, t, outCell);
    } else {
      const VF h00 = code(r0), h10 = codeHigh(r0), h01 = code(r1), h11 = codeHigh(r1);
      const VF top = hn::Max(hn::Max(h00, h10), hn::Max(h01, h11));
      const auto near = hn::AndNot(skip, hn::And(active, hn::Le(lowest, top)));
      met = SolveCell(df, rays, near, t, outCell, fi, fj, Corners<DF>{h00, h10, h01, h11}, hit);
    }
    // On: the lanes that neither met the surface here (or were parked at it) nor stopped; a
    // parked lane keeps what its move told until it walks on.
    active = hn::AndNot(met, moves);
    t = hn::IfThenElse(moves, out, t);
    const auto newSquare = hn::RebindMask(df, hn::Or(hn::Not(hn::Eq(hn::And(ni, squareMask), si)),
                                                     hn::Not(hn::Eq(hn::And(nj, squareMask), sj))));
    entered = hn::Or(hn::And(moves, newSquare), hn::AndNot(moves, entered));
    ci = ni, cj = nj;
    r0 = n0, r1 = n1, rTop = nTop;
  }
  hn::Store(hit, df, L.hit + first);
  hn::Store(hn::IfThenElse(budget.spent, t, inf), df, L.reached + first);
}

void WalkPacket(const PacketGrid& grid, PacketLanes& lanes, int maxCells) {
  const hn::CappedTag<float, kPacketRays> df;
  for (size_t first = 0; first < size_t(kPacketRays); first += hn::Lanes(df)) {
    if (grid.cellTop)
      WalkLanes<true>(df, grid, lanes, first, maxCells);
    else
      WalkLanes<false>(df, grid, lanes, first, maxCells);
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::terrain
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sv::terrain {
HWY_EXPORT(WalkPacket);

void walkPacket(const PacketGrid& grid, PacketLanes& lanes, int count, int maxCells) {
  // The lanes past `count`: idle.
  for (int l = std::max(count, 0); l < kPacketRays; ++l) {
    lanes.t0[l] = 0, lanes.t1[l] = -1;
    lanes.x0[l] = lanes.y0[l] = lanes.z0[l] = lanes.ex[l] = lanes.ey[l] = lanes.ez[l] = 0;
  }
  HWY_DYNAMIC_DISPATCH(WalkPacket)(grid, lanes, maxCells);
}

}  // namespace sv::terrain
#endif  // HWY_ONCE
