// Based on: SPEC §12 (multi-level ray casting: subdivision in depth, conservative bounds, the
// level from the projected size), §11 (max-LOD maps, interpolation below the finest level).
#include "terrain/caster.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

namespace sv::terrain {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Cells a ray walks directly from its start before marching (Caster::cast).
constexpr double kDirectCells = 8;

// The ray over [sa, sb] walked cell by cell (Amanatides–Woo) over cells [0, cellsX) × [0, cellsY),
// clipped to the footprint [0, footX] × [0, footY] (slabs: beyond it there is no surface, and
// where the ray enters it below the heights it meets the prism's wall): `cell(i, j, s, out)` for
// each cell the ray is in over [s, out], until one returns a hit (not NaN).
template <class Cell>
double walkCells(const GridRay& r, int cellsX, int cellsY, double footX, double footY, double sa,
                 double sb, Cell&& cell) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  for (const auto& [p0, e, hi] : {std::tuple{r.x0, r.ex, footX}, std::tuple{r.y0, r.ey, footY}}) {
    if (e == 0) {
      if (p0 < 0 || p0 > hi) return kNaN;
      continue;
    }
    const double t0 = (0 - p0) / e, t1 = (hi - p0) / e;
    sa = std::max(sa, std::min(t0, t1));
    sb = std::min(sb, std::max(t0, t1));
  }
  if (!(sa <= sb)) return kNaN;
  double s = sa;
  // The cell holding the point at s (the last row and column belong to the cells before them).
  int i = std::clamp(int(std::floor(r.x0 + s * r.ex)), 0, cellsX - 1),
      j = std::clamp(int(std::floor(r.y0 + s * r.ey)), 0, cellsY - 1);
  // The parameters where the ray crosses the next column and row boundary, advanced by a cell's
  // worth each step.
  const int stepI = r.ex > 0 ? 1 : -1, stepJ = r.ey > 0 ? 1 : -1;
  const double dtx = r.ex != 0 ? std::fabs(1 / r.ex) : kInf;
  const double dty = r.ey != 0 ? std::fabs(1 / r.ey) : kInf;
  double tx = r.ex != 0 ? ((r.ex > 0 ? i + 1 : i) - r.x0) / r.ex : kInf;
  double ty = r.ey != 0 ? ((r.ey > 0 ? j + 1 : j) - r.y0) / r.ey : kInf;
  for (;;) {
    const double out = std::min(std::min(tx, ty), sb);  // where the ray leaves the cell
    if (const double hit = cell(i, j, s, out); !std::isnan(hit)) return hit;
    if (out >= sb) break;
    s = out;
    if (tx <= ty)
      i += stepI, tx += dtx;
    else
      j += stepJ, ty += dty;
    if (i < 0 || j < 0 || i >= cellsX || j >= cellsY) break;
  }
  return kNaN;
}

// The first root of f in the bracket [a, b], f(a) = fa > 0 ≥ f(b) = fb, to `tolerance`: regula
// falsi with the Illinois step while both ends are finite, bisection across the footprint's edge
// (fa = +∞).
template <class F>
double refineRoot(double a, double fa, double b, double fb, double tolerance, F&& f) {
  int side = 0;
  for (int it = 0; it < 60 && b - a > tolerance; ++it) {
    const double m =
        std::isfinite(fa) && fa - fb > 0 ? b - fb * (b - a) / (fb - fa) : 0.5 * (a + b);
    const double mm = (m > a && m < b) ? m : 0.5 * (a + b);
    const double fm = f(mm);
    if (fm <= 0) {
      b = mm, fb = fm;
      if (side == -1) fa *= 0.5;
      side = -1;
    } else {
      a = mm, fa = fm;
      if (side == 1) fb *= 0.5;
      side = 1;
    }
  }
  return b;
}

// Catmull–Rom's basis as powers of t (height_field.cpp's weights): w_c(t) = Σ_k kBasis[k][c]·t^k.
constexpr double kBasis[4][4] = {
    {0, 1, 0, 0}, {-0.5, 0, 0.5, 0}, {1, -2.5, 2, -0.5}, {-0.5, 1.5, -1.5, 0.5}};

}  // namespace

Caster::Caster(const HeightField& field, const Pyramid& pyramid, Interpolation interp,
               const Placement& placement)
    : field_(field), pyramid_(pyramid), interp_(interp), placement_(placement) {
  // u = refU + x, v = refV − z; gx = (u − originU)/spacingU, gy = (originV − v)/spacingV.
  ax_ = 1 / field.spacingU;
  bx_ = (placement.refU - field.originU) / field.spacingU;
  ay_ = 1 / field.spacingV;
  by_ = (field.originV - placement.refV) / field.spacingV;
  margin_ = 1e-9 * (std::fabs(field.offset) + 65535 * field.scale) + 1e-12;
}

Caster::MapPoint Caster::toMapOnSphere(Vec3d p) const {
  const double R = placement_.radius;
  // Gnomonic: the tangent plane y = 0 met by the line from the centre (0, −R, 0) through p.
  const Vec3d d{p.x, p.y + R, p.z};
  const double r = length(d);
  if (!(d.y > 0)) return {kInf, kInf, r - R};  // beyond the hemisphere: off every table
  const double k = R / d.y;
  return {ax_ * (d.x * k) + bx_, ay_ * (d.z * k) + by_, r - R};
}

Vec3d Caster::toWorld(double gx, double gy, double h) const {
  const double x = (gx - bx_) / ax_, z = (gy - by_) / ay_;
  const double R = placement_.radius;
  if (R <= 0) return {x, h, z};
  const Vec3d d = normalize(Vec3d{x, R, z});
  return Vec3d{0, -R, 0} + d * (R + h);
}

namespace {

// Level k's bilinear surface at grid (gx, gy), in codes, and its derivatives per grid step.
double meanSurface(const Pyramid::MeanLevel& m, double gx, double gy, double* dx, double* dy) {
  const double x = std::clamp(gx / m.step, 0.0, double(m.width - 1));
  const double y = std::clamp(gy / m.step, 0.0, double(m.height - 1));
  const int i = std::min(int(x), m.width - 2), j = std::min(int(y), m.height - 2);
  const double u = x - i, v = y - j;
  const double h00 = m.code(i, j), h10 = m.code(i + 1, j), h01 = m.code(i, j + 1),
               h11 = m.code(i + 1, j + 1);
  const double top = h00 + (h10 - h00) * u, bottom = h01 + (h11 - h01) * u;
  if (dx) *dx = ((h10 - h00) * (1 - v) + (h11 - h01) * v) / m.step;
  if (dy) *dy = (bottom - top) / m.step;
  return top + (bottom - top) * v;
}

}  // namespace

double Caster::surface(double gx, double gy, int level) const {
  if (!(gx >= 0 && gy >= 0 && gx <= field_.width - 1 && gy <= field_.height - 1))
    return std::numeric_limits<double>::quiet_NaN();
  if (level >= pyramid_.gridLevel()) return interpolate(field_, interp_, gx, gy);
  return field_.offset + field_.scale * meanSurface(pyramid_.mean(level), gx, gy, nullptr, nullptr);
}

Vec3d Caster::normal(double gx, double gy, Vec3d* eastOut, Vec3d* northOut, int level) const {
  double dx = 0, dy = 0;
  if (level >= pyramid_.gridLevel()) {
    interpolate(field_, interp_, gx, gy, &dx, &dy);
  } else {
    meanSurface(pyramid_.mean(level), gx, gy, &dx, &dy);
    dx *= field_.scale, dy *= field_.scale;
  }
  // Slopes per metre east and north (gy grows southward).
  const double se = dx / field_.spacingU, sn = -dy / field_.spacingV;
  Vec3d up{0, 1, 0}, east{1, 0, 0}, north{0, 0, -1};
  if (placement_.radius > 0) {
    up = normalize(toWorld(gx, gy, 0) - Vec3d{0, -placement_.radius, 0});
    east = normalize(east - up * dot(east, up));
    north = normalize(cross(up, east));
  }
  if (eastOut) *eastOut = east;
  if (northOut) *northOut = north;
  return normalize(up - east * se - north * sn);
}

double Caster::gridSpeed(const Bundle& b) const {
  double v = 0;
  for (const Vec3d& d : b.corner) v = std::max({v, std::fabs(d.x) * ax_, std::fabs(d.z) * ay_});
  return std::max(v, 1e-300);
}

Caster::Box Caster::bounds(const Bundle& b, double sa, double sb) const {
  if (placement_.radius <= 0) {
    // Affine: each coordinate's extremes over the eight corners origin + {sa, sb}·corner.
    Box box{kInf, -kInf, kInf, -kInf, kInf, -kInf};
    for (const Vec3d& d : b.corner) {
      const double x0 = d.x * sa, x1 = d.x * sb, y0 = d.y * sa, y1 = d.y * sb, z0 = d.z * sa,
                   z1 = d.z * sb;
      box.gx0 = std::min({box.gx0, x0, x1});
      box.gx1 = std::max({box.gx1, x0, x1});
      box.h0 = std::min({box.h0, y0, y1});
      box.h1 = std::max({box.h1, y0, y1});
      box.gy0 = std::min({box.gy0, z0, z1});
      box.gy1 = std::max({box.gy1, z0, z1});
    }
    const Vec3d& o = b.origin;
    return {ax_ * (o.x + box.gx0) + bx_,
            ax_ * (o.x + box.gx1) + bx_,
            ay_ * (o.z + box.gy0) + by_,
            ay_ * (o.z + box.gy1) + by_,
            o.y + box.h0,
            o.y + box.h1};
  }
  // The sphere: the hull of the eight points maps by central projection to the hull of their
  // images (a projective map keeps convexity in front of its centre); heights from the farthest
  // point and the distance from the centre to the points' box.
  const double R = placement_.radius;
  Box box{kInf, -kInf, kInf, -kInf, kInf, -kInf};
  Vec3d lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
  for (const Vec3d& d : b.corner)
    for (double s : {sa, sb}) {
      const Vec3d p = b.origin + d * s;
      const MapPoint m = toMap(p);
      if (!std::isfinite(m.gx)) return {-kInf, kInf, -kInf, kInf, -kInf, kInf};
      box.gx0 = std::min(box.gx0, m.gx), box.gx1 = std::max(box.gx1, m.gx);
      box.gy0 = std::min(box.gy0, m.gy), box.gy1 = std::max(box.gy1, m.gy);
      box.h1 = std::max(box.h1, m.h);
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
  const Vec3d c{0, -R, 0};
  const Vec3d nearest{std::clamp(c.x, lo.x, hi.x), std::clamp(c.y, lo.y, hi.y),
                      std::clamp(c.z, lo.z, hi.z)};
  box.h0 = length(nearest - c) - R;
  return box;
}

double Caster::march(const Bundle& b, double s, double s1, double footprint, double pixel,
                     CastCounters& c) const {
  ++c.windows;
  const int finest = pyramid_.gridLevel() - 1;
  const double speed = gridSpeed(b);
  // The level whose nodes are at least as wide as the bundle at s (finer nodes bound it no
  // tighter), at most the finest stored.
  auto levelFor = [&](double at) {
    const double w = footprint * at;
    if (!(w > 1)) return finest;
    return std::clamp(pyramid_.gridLevel() - int(std::ceil(std::log2(w))), 0, finest);
  };
  // The bundle's longest stretch on the ground: its coarsest level of detail.
  double stretchMax = 1;
  for (const Vec3d& d : b.corner) stretchMax = std::max(stretchMax, stretch(d));
  auto stopAt = [&](double at) { return std::min(levelFor(at), lodLevel(at, pixel, stretchMax)); };
  int level = stopAt(s);
  int empties = 0;
  while (s < s1) {
    const int stop = stopAt(s);
    level = std::min(level, stop);
    const double nodeSize = pyramid_.nodeCells(level);
    const double sb = std::min(s + nodeSize / speed, s1);
    ++c.steps;
    const Box box = bounds(b, s, sb);
    const double inv = 1 / nodeSize;
    // Where a mean level is drawn, one node more on every side: its surface over a node reads its
    // neighbours' samples (pyramid.h), and stops at `level` or finer never read further.
    const int grow = lodLevel(s, pixel, stretchMax) < pyramid_.gridLevel() ? 1 : 0;
    const Pyramid::Range r =
        pyramid_.range(level, int(std::floor(std::max(box.gx0, -1.0) * inv)) - grow,
                       int(std::floor(std::min(box.gx1, 1e9) * inv)) + grow,
                       int(std::floor(std::max(box.gy0, -1.0) * inv)) - grow,
                       int(std::floor(std::min(box.gy1, 1e9) * inv)) + grow);
    if (r.hi < r.lo || box.h0 > r.hi + margin_) {
      // Wholly above the surface (or beyond the table): on, and after two such steps coarser.
      s = sb;
      if (++empties >= 2 && level > 0) --level, empties = 0;
      continue;
    }
    empties = 0;
    if (level < stop) {
      ++level;  // finer nodes may clear the step
      continue;
    }
    return s;
  }
  return s1;
}

double Caster::above(Vec3d origin, Vec3d dir, double s, int level) const {
  const MapPoint m = toMap(origin + dir * s);
  const double h = surface(m.gx, m.gy, level);
  return std::isnan(h) ? kInf : m.h - h;
}

double Caster::solve(Vec3d o, Vec3d d, double sa, double sb, double fa, int level) const {
  if (fa <= 0) return sa;
  // Samples an eighth of a cell apart (on the plane a cell's bilinear surface along a line is a
  // parabola, its bicubic one of degree 6, and on a sphere neither: eight samples a cell find every
  // crossing but a ridge the ray grazes by less than the surface's rise over an eighth of a cell —
  // four missed one on the sphere test's grazing rays, tests/terrain/caster_test.cpp).
  const double along = (sb - sa) * gridSpeed(Bundle{o, {d, d, d, d}}) /
                       pyramid_.nodeCells(std::min(level, pyramid_.gridLevel()));
  const int n = std::clamp(int(std::ceil(8 * along)), 1, 64);
  double s0 = sa, f0 = fa;
  for (int k = 1; k <= n; ++k) {
    const double s1 = k == n ? sb : sa + (sb - sa) * k / n;
    const double f1 = above(o, d, s1, level);
    if (f1 <= 0) {
      const double tolerance = 1e-4 / std::max(gridSpeed(Bundle{o, {d, d, d, d}}), 1e-300);
      return refineRoot(s0, f0, s1, f1, tolerance,
                        [&](double at) { return above(o, d, at, level); });
    }
    s0 = s1, f0 = f1;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

GridRay Caster::gridRay(Vec3d o, Vec3d d, double step) const {
  const double k = 1 / step, toCode = 1 / field_.scale;
  return {(ax_ * o.x + bx_) * k, (ay_ * o.z + by_) * k, (o.y - field_.offset) * toCode,
          ax_ * d.x * k,         ay_ * d.z * k,         d.y * toCode};
}

double Caster::solveBilinear(Vec3d o, Vec3d d, double sa, double sb, int level) const {
  const Pyramid::MeanLevel m = pyramid_.mean(level);
  const GridRay r = gridRay(o, d, m.step);
  // The table's footprint, in the level's steps (its last samples may lie beyond it).
  const double footX = (field_.width - 1) / m.step, footY = (field_.height - 1) / m.step;
  return walkCells(
      r, m.width - 1, m.height - 1, footX, footY, sa, sb, [&](int i, int j, double s, double out) {
        const double h00 = m.code(i, j), h10 = m.code(i + 1, j), h01 = m.code(i, j + 1),
                     h11 = m.code(i + 1, j + 1);
        // Solved only where the ray's lowest point in the cell is not above its highest corner.
        if (r.z0 + (r.ez < 0 ? out : s) * r.ez > std::max(std::max(h00, h10), std::max(h01, h11)))
          return std::numeric_limits<double>::quiet_NaN();
        // h = a + b·u + c·v + g·u·v over the cell, u = x − i, v = y − j; along the ray from s:
        // u = u0 + t·ex, v = v0 + t·ey, so z − h = A·t² + B·t + C.
        const double b = h10 - h00, c = h01 - h00, g = h11 - h10 - h01 + h00;
        const double u0 = r.x0 + s * r.ex - i, v0 = r.y0 + s * r.ey - j;
        const double A = -g * r.ex * r.ey;
        const double B = r.ez - b * r.ex - c * r.ey - g * (u0 * r.ey + v0 * r.ex);
        const double C = r.z0 + s * r.ez - (h00 + b * u0 + c * v0 + g * u0 * v0);
        const double span = out - s;
        if (C <= 0) return s;  // under the surface already (the prism's wall, or the start)
        double root = kInf;
        if (std::fabs(A) * span < 1e-12 * (std::fabs(B) + std::fabs(C) / std::max(span, 1e-300))) {
          if (B < 0) root = -C / B;
        } else {
          const double disc = B * B - 4 * A * C;
          if (disc >= 0) {
            // The stable pair: q = −(B + sign(B)·√disc)/2, roots q/A and C/q.
            const double q = -0.5 * (B + std::copysign(std::sqrt(disc), B));
            const double r1 = q / A, r2 = q != 0 ? C / q : kInf;
            for (double x : {r1, r2})
              if (x >= 0 && x < root) root = x;
          }
        }
        return root <= span ? s + root : std::numeric_limits<double>::quiet_NaN();
      });
}

double Caster::solveBicubic(Vec3d o, Vec3d d, double sa, double sb) const {
  const HeightField& f = field_;
  const GridRay r = gridRay(o, d, 1);
  const Pyramid::TopLevel bounds = pyramid_.cellTops();
  return walkCells(r, f.width - 1, f.height - 1, f.width - 1, f.height - 1, sa, sb,
                   [&](int i, int j, double s, double out) {
                     // Solved only where the ray may touch the cell's Bézier hull.
                     double top = kInf;
                     if (bounds.top) {
                       const uint16_t t = bounds.top[size_t(j) * size_t(bounds.width) + size_t(i)];
                       if (t != Pyramid::kNoTop) top = t;
                     }
                     if (r.z0 + (r.ez < 0 ? out : s) * r.ez > top)
                       return std::numeric_limits<double>::quiet_NaN();
                     return solveBicubicCell(r, i, j, s, out, bounds.top != nullptr);
                   });
}

double Caster::solveBicubicCell(const GridRay& r, int i, int j, double s, double out,
                                bool bounded) const {
  double h[4][4];
  cellSamples(field_, i, j, h);
  if (!bounded && r.z0 + (r.ez < 0 ? out : s) * r.ez > bezierTop(h))
    return std::numeric_limits<double>::quiet_NaN();
  // The patch as a polynomial: P(u, v) = Σ a[l][k]·u^k·v^l, a = B·H·Bᵀ over the basis.
  double rows[4][4] = {}, a[4][4] = {};
  for (int y = 0; y < 4; ++y)
    for (int k = 0; k < 4; ++k)
      for (int x = 0; x < 4; ++x) rows[y][k] += kBasis[k][x] * h[y][x];
  for (int l = 0; l < 4; ++l)
    for (int k = 0; k < 4; ++k)
      for (int y = 0; y < 4; ++y) a[l][k] += kBasis[l][y] * rows[y][k];
  // Along the ray from s (τ = t − s): u = u0 + τ·ex, v = v0 + τ·ey, so P is a polynomial of degree
  // 6 in τ and f(τ) = z − P its height above the patch: composed once, then each evaluation is
  // Horner's rule of degree 6.
  const double u0 = r.x0 + s * r.ex - i, v0 = r.y0 + s * r.ey - j;
  double U[4][4] = {{1}}, V[4][4] = {{1}};  // U[k]: (u0 + τ·ex)^k's coefficients
  for (int k = 1; k < 4; ++k)
    for (int c = 0; c <= k; ++c) {
      U[k][c] = (c < k ? U[k - 1][c] * u0 : 0) + (c > 0 ? U[k - 1][c - 1] * r.ex : 0);
      V[k][c] = (c < k ? V[k - 1][c] * v0 : 0) + (c > 0 ? V[k - 1][c - 1] * r.ey : 0);
    }
  double f[7] = {r.z0 + s * r.ez, r.ez, 0, 0, 0, 0, 0};
  for (int l = 0; l < 4; ++l) {
    double q[4] = {};  // Σ_k a[l][k]·U[k]
    for (int k = 0; k < 4; ++k)
      for (int c = 0; c <= k; ++c) q[c] += a[l][k] * U[k][c];
    for (int c = 0; c <= l; ++c)
      for (int e = 0; e < 4; ++e) f[c + e] -= V[l][c] * q[e];
  }
  auto above = [&](double t) {
    const double x = t - s;
    return (((((f[6] * x + f[5]) * x + f[4]) * x + f[3]) * x + f[2]) * x + f[1]) * x + f[0];
  };
  // Samples an eighth of a cell apart along the ray (solve()'s rule), then the bracket refined.
  const double speed = std::hypot(r.ex, r.ey);  // cells per unit s
  const double fs = above(s);
  if (fs <= 0) return s;
  const int n = std::clamp(int(std::ceil(8 * (out - s) * speed)), 1, 64);
  double s0 = s, f0 = fs;
  for (int k = 1; k <= n; ++k) {
    const double s1 = k == n ? out : s + (out - s) * k / n;
    const double f1 = above(s1);
    if (f1 <= 0) return refineRoot(s0, f0, s1, f1, 1e-4 / std::max(speed, 1e-300), above);
    s0 = s1, f0 = f1;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

void Caster::walkPacket(Packet& p, int level, int maxCells, CastCounters& c) const {
  walkLanes(p, p.s0, p.s1, p.hit, p.reached, level, maxCells, c);
}

void Caster::walkLanes(const Packet& p, const double* s0, const double* s1, double* hit,
                       double* reached, int level, int maxCells, CastCounters& c) const {
  // The level's grid, as solveBilinear's: x = x0 + s·ex in its sample steps, z in table codes.
  const Pyramid::MeanLevel m = pyramid_.mean(level);
  const double k = 1 / m.step, toCode = 1 / field_.scale;
  const Vec3d& o = p.origin;
  const double x0 = (ax_ * o.x + bx_) * k, y0 = (ay_ * o.z + by_) * k;
  const double z0 = (o.y - field_.offset) * toCode;
  const int count = std::clamp(p.count, 0, kPacketRays);
  // The packet's reference s (its lanes' t = 0) and anchor: the first live lane's start, the
  // sample at the corner of its cell (clamped to the grid), and the code nearest its height.
  double sRef = kInf;
  int first = -1;
  for (int l = 0; l < count; ++l) {
    hit[l] = std::numeric_limits<double>::quiet_NaN();
    reached[l] = s1[l];
    if (!(s0[l] <= s1[l])) continue;
    if (first < 0) first = l;
    sRef = std::min(sRef, s0[l]);
  }
  if (first < 0) return;
  PacketGrid g;
  g.q = m.q, g.width = m.width, g.cellsX = m.width - 1, g.cellsY = m.height - 1;
  const Vec3d& d = p.dir[first];
  auto corner = [](double v, int cells) {
    return int(std::clamp(std::floor(std::clamp(v, 0.0, double(cells))), 0.0, double(cells - 1)));
  };
  const Pyramid::TopLevel tops = pyramid_.tops(level);
  g.top = tops.top, g.topWidth = tops.width;
  if (level >= pyramid_.gridLevel() && interp_ == Interpolation::bicubic)
    g.cellTop = pyramid_.cellTops().top;
  // The anchor: the corner of the skip map's square holding the first lane's start.
  g.anchorI = corner(x0 + sRef * ax_ * d.x * k, g.cellsX) & ~(Pyramid::kTopCells - 1);
  g.anchorJ = corner(y0 + sRef * ay_ * d.z * k, g.cellsY) & ~(Pyramid::kTopCells - 1);
  // An integer code (a float holds it exactly below 2^24).
  g.anchorZ = float(std::clamp(std::round(z0 + sRef * d.y * toCode), -8388608.0, 8388608.0));
  g.footX0 = float(-g.anchorI), g.footX1 = float((field_.width - 1) * k - g.anchorI);
  g.footY0 = float(-g.anchorJ), g.footY1 = float((field_.height - 1) * k - g.anchorJ);
  PacketLanes lanes;
  for (int l = 0; l < count; ++l) {
    if (!(s0[l] <= s1[l])) {
      lanes.t0[l] = 0, lanes.t1[l] = -1;  // idle
      lanes.x0[l] = lanes.y0[l] = lanes.z0[l] = lanes.ex[l] = lanes.ey[l] = lanes.ez[l] = 0;
      continue;
    }
    const double ex = ax_ * p.dir[l].x * k, ey = ay_ * p.dir[l].z * k, ez = p.dir[l].y * toCode;
    lanes.x0[l] = float(x0 + sRef * ex - g.anchorI);
    lanes.y0[l] = float(y0 + sRef * ey - g.anchorJ);
    lanes.z0[l] = float(z0 + sRef * ez - double(g.anchorZ));
    lanes.ex[l] = float(ex), lanes.ey[l] = float(ey), lanes.ez[l] = float(ez);
    lanes.t0[l] = float(s0[l] - sRef), lanes.t1[l] = float(s1[l] - sRef);
    ++c.lanes;
  }
  terrain::walkPacket(g, lanes, count, maxCells);
  for (int l = 0; l < count; ++l) {
    if (!(s0[l] <= s1[l])) continue;
    if (!std::isnan(lanes.hit[l])) hit[l] = sRef + double(lanes.hit[l]), ++c.hits;
    if (std::isfinite(lanes.reached[l])) reached[l] = sRef + double(lanes.reached[l]);
  }
}

void Caster::walkPacketLevels(Packet& p, double pixel, double stretch, int maxCells,
                              CastCounters& c) const {
  const int n = pyramid_.gridLevel();
  const int count = std::clamp(p.count, 0, kPacketRays);
  // Each lane's span not walked yet (from > to: none), and a round's spans and results.
  double from[kPacketRays], to[kPacketRays];
  double walkFrom[kPacketRays], walkTo[kPacketRays], hit[kPacketRays], reached[kPacketRays];
  const uint64_t lanes = c.lanes;  // a lane counts once, however many levels it walks
  uint64_t walked = 0;
  for (int l = 0; l < count; ++l) {
    from[l] = p.s0[l], to[l] = p.s1[l];
    p.hit[l] = std::numeric_limits<double>::quiet_NaN(), p.reached[l] = p.s0[l];
  }
  // Each round a coarser level (at `end`, where the last stopped, lodLevel is still that level).
  for (int last = n + 1;;) {
    double nearest = kInf;
    for (int l = 0; l < count; ++l)
      if (from[l] <= to[l]) nearest = std::min(nearest, from[l]);
    if (!std::isfinite(nearest) || last == 0) break;
    const int level = std::min(lodLevel(nearest, pixel, stretch), last - 1);
    if (!packetsApply()) break;  // the lanes left go on alone from their starts
    if (last > n)                // the first round: its lanes are the packet's rays
      for (int l = 0; l < count; ++l) walked += from[l] <= to[l];
    last = level;
    // lodLevel is `level` while pixel·s·stretch ≤ 2^(n − level).
    const double end =
        pixel > 0 && level > 0 ? std::ldexp(1.0, n - level) / (pixel * stretch) : kInf;
    for (int l = 0; l < count; ++l)
      if (from[l] <= to[l] && from[l] < end) {
        walkFrom[l] = from[l], walkTo[l] = std::min(to[l], end);
      } else {
        walkFrom[l] = 1, walkTo[l] = 0;  // idle this round
      }
    walkLanes(p, walkFrom, walkTo, hit, reached, level, maxCells, c);
    for (int l = 0; l < count; ++l) {
      if (!(walkFrom[l] <= walkTo[l])) continue;
      const bool met = !std::isnan(hit[l]);
      if (met) p.hit[l] = hit[l];
      p.reached[l] = reached[l];
      if (met || reached[l] >= to[l] || reached[l] < walkTo[l]) {
        from[l] = 1, to[l] = 0;  // finished, or stopped: alone from `reached`
      } else {
        from[l] = walkTo[l];  // on at the next level
      }
    }
  }
  c.lanes = lanes + walked;
}

double Caster::solveAt(Vec3d o, Vec3d d, double sa, double sb, int level) const {
  const bool bilinear = level < pyramid_.gridLevel() || interp_ == Interpolation::bilinear;
  if (placement_.radius <= 0 && bilinear) return solveBilinear(o, d, sa, sb, level);
  if (placement_.radius <= 0) return solveBicubic(o, d, sa, sb);
  return solve(o, d, sa, sb, above(o, d, sa, level), level);
}

double Caster::cast(Vec3d o, Vec3d d, double s, double s1, CastCounters& c, double pixel) const {
  ++c.rays;
  const Bundle ray{o, {d, d, d, d}};
  const double speed = gridSpeed(ray), rayStretch = stretch(d);
  const int n = pyramid_.gridLevel();
  // Solves [s, s + cells of the level of detail at s): the hit, or NaN and s moved past them.
  auto solveAhead = [&](double cells) {
    const int level = lodLevel(s, pixel, rayStretch);
    const double sb = std::min(s + cells * pyramid_.nodeCells(std::min(level, n)) / speed, s1);
    ++c.solves;
    const double hit = solveAt(o, d, s, sb, level);
    if (!std::isnan(hit))
      ++c.hits;
    else
      s = sb;
    return hit;
  };
  // A bundle's start lies close to where its rays meet the ground: the first few cells walked
  // directly, before any march (whose steps cost more than a cell's solve).
  if (const double hit = solveAhead(kDirectCells); !std::isnan(hit)) return hit;
  while (s < s1) {
    s = march(ray, s, s1, 0, pixel, c);
    if (s >= s1) break;
    // Two cells of the level of detail (the finest stored level's node, at level n).
    if (const double hit = solveAhead(2); !std::isnan(hit)) return hit;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

}  // namespace sv::terrain
