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

// One vector of lanes, from lane `first`: each lane's span clipped to the table's footprint, then
// walked until it is done or has taken maxCells steps — per lane Caster::solveBilinear's cells, in
// float, with the skip map's squares passed at once (SPEC §12: a node the ray stays above is
// skipped). Per step a lane is in one cell; where it has just entered a square, it first asks
// whether its ray stays above the square's top from there until it leaves the square: then the
// step takes it to the next square, else it solves the cell as any other.
template <bool kBicubic, class DF>
void WalkLanes(DF df, const PacketGrid& g, PacketLanes& L, size_t first, int maxCells) {
  const hn::RebindToSigned<DF> di;
  const hn::RebindToUnsigned<DF> du;
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
  const VI low16 = hn::Set(di, 0xFFFF);
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
  auto code = [&](VI r) { return hn::Sub(hn::ConvertTo(df, hn::And(r, low16)), anchorZ); };
  auto codeHigh = [&](VI r) {
    return hn::Sub(hn::ConvertTo(df, hn::BitCast(di, hn::ShiftRight<16>(hn::BitCast(du, r)))),
                   anchorZ);
  };
  const VI noTop = hn::Set(di, Pyramid::kNoTop);
  auto bounded = [&](VI r) { return hn::RebindMask(df, hn::Lt(hn::And(r, low16), noTop)); };
  auto entered = active;           // lanes that have just entered a square
  auto stopped = hn::Lt(t, zero);  // bicubic: lanes stopped at the cell they may touch (none yet)
  VI r0, r1, rTop;
  gather(ci, cj, r0, r1, rTop);
  for (int steps = 0; steps < maxCells && !hn::AllFalse(df, active); ++steps) {
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
    auto in = [&](VI v, VI lo, VI hi) {
      return hn::And(hn::Gt(v, hn::Sub(lo, hn::Set(di, 1))),
                     hn::Lt(v, hn::Add(hi, hn::Set(di, 1))));
    };
    const auto inside = hn::And(in(nextI, loI, hiI), in(nextJ, loJ, hiJ));
    const auto moves = hn::And(goOn, hn::RebindMask(df, inside));
    const auto movesI = hn::RebindMask(di, moves);
    const VI ni = hn::IfThenElse(movesI, nextI, ci), nj = hn::IfThenElse(movesI, nextJ, cj);
    VI n0, n1, nTop;
    gather(ni, nj, n0, n1, nTop);
    // This cell, for the lanes that did not pass its square: solved only where the ray's lowest
    // point in it is not above its highest corner — or, bicubic, left where it is not above the
    // cell's bound, to be solved alone.
    const VF lowest = hn::Add(z0, hn::Mul(hn::IfThenElse(hn::Lt(ez, zero), outCell, t), ez));
    hn::Mask<DF> met;
    if constexpr (kBicubic) {
      met =
          hn::AndNot(skip, hn::And(active, hn::Or(hn::Not(bounded(r0)), hn::Le(lowest, code(r0)))));
      stopped = hn::Or(stopped, met);
    } else {
      const VF h00 = code(r0), h10 = codeHigh(r0), h01 = code(r1), h11 = codeHigh(r1);
      const VF top = hn::Max(hn::Max(h00, h10), hn::Max(h01, h11));
      const auto near = hn::AndNot(skip, hn::And(active, hn::Le(lowest, top)));
      met = SolveCell(df, CellRays<DF>{x0, y0, z0, ex, ey, ez}, near, t, outCell, fi, fj,
                      Corners<DF>{h00, h10, h01, h11}, hit);
    }
    // On: the lanes that neither met the surface here (or stopped at it) nor stopped; a lane
    // stopped at a cell keeps its t, the cell's entry.
    active = hn::AndNot(met, moves);
    t = hn::IfThenElse(active, out, t);
    entered = hn::RebindMask(df, hn::Or(hn::Not(hn::Eq(hn::And(ni, squareMask), si)),
                                        hn::Not(hn::Eq(hn::And(nj, squareMask), sj))));
    ci = ni, cj = nj;
    r0 = n0, r1 = n1, rTop = nTop;
  }
  hn::Store(hit, df, L.hit + first);
  hn::Store(hn::IfThenElse(hn::Or(active, stopped), t, inf), df, L.reached + first);
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
