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

double length(Vec3d v) { return std::sqrt(dot(v, v)); }
Vec3d cross(Vec3d a, Vec3d b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

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

Caster::MapPoint Caster::toMap(Vec3d p) const {
  const double R = placement_.radius;
  if (R <= 0) return {ax_ * p.x + bx_, ay_ * p.z + by_, p.y};
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

double Caster::surface(double gx, double gy) const {
  if (!(gx >= 0 && gy >= 0 && gx <= field_.width - 1 && gy <= field_.height - 1))
    return std::numeric_limits<double>::quiet_NaN();
  return interpolate(field_, interp_, gx, gy);
}

Vec3d Caster::normal(double gx, double gy, Vec3d* eastOut, Vec3d* northOut) const {
  double dx = 0, dy = 0;
  interpolate(field_, interp_, gx, gy, &dx, &dy);
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
  for (const Vec3d& d : b.corner)
    v = std::max({v, std::fabs(d.x) * ax_, std::fabs(d.z) * ay_});
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
    return {ax_ * (o.x + box.gx0) + bx_, ax_ * (o.x + box.gx1) + bx_,
            ay_ * (o.z + box.gy0) + by_, ay_ * (o.z + box.gy1) + by_,
            o.y + box.h0,                o.y + box.h1};
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

double Caster::march(const Bundle& b, double s, double s1, double footprint,
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
  int level = levelFor(s);
  int empties = 0;
  while (s < s1) {
    const int stop = levelFor(s);
    level = std::min(level, stop);
    const double nodeSize = pyramid_.nodeCells(level);
    const double sb = std::min(s + nodeSize / speed, s1);
    ++c.steps;
    const Box box = bounds(b, s, sb);
    const double inv = 1 / nodeSize;
    const Pyramid::Range r = pyramid_.range(
        level, int(std::floor(std::max(box.gx0, -1.0) * inv)),
        int(std::floor(std::min(box.gx1, 1e9) * inv)),
        int(std::floor(std::max(box.gy0, -1.0) * inv)),
        int(std::floor(std::min(box.gy1, 1e9) * inv)));
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

double Caster::above(Vec3d origin, Vec3d dir, double s) const {
  const MapPoint m = toMap(origin + dir * s);
  const double h = surface(m.gx, m.gy);
  return std::isnan(h) ? kInf : m.h - h;
}

double Caster::solve(Vec3d o, Vec3d d, double sa, double sb, double fa) const {
  if (fa <= 0) return sa;
  // Samples an eighth of a cell apart (on the plane a cell's bilinear surface along a line is a
  // parabola, its bicubic one of degree 6, and on a sphere neither: eight samples a cell find every
  // crossing but a ridge the ray grazes by less than the surface's rise over an eighth of a cell —
  // four missed one on the sphere test's grazing rays, tests/terrain/caster_test.cpp).
  const double along = (sb - sa) * gridSpeed(Bundle{o, {d, d, d, d}});
  const int n = std::clamp(int(std::ceil(8 * along)), 1, 64);
  double s0 = sa, f0 = fa;
  for (int k = 1; k <= n; ++k) {
    const double s1 = k == n ? sb : sa + (sb - sa) * k / n;
    const double f1 = above(o, d, s1);
    if (f1 <= 0) {
      // A bracket [s0, s1], f0 > 0 ≥ f1: regula falsi with the Illinois step while both ends are
      // finite, bisection across the footprint's edge (f0 = +∞).
      double a = s0, fa2 = f0, b = s1, fb = f1;
      int side = 0;
      const double tolerance = 1e-4 / std::max(gridSpeed(Bundle{o, {d, d, d, d}}), 1e-300);
      for (int it = 0; it < 60 && b - a > tolerance; ++it) {
        const double m =
            std::isfinite(fa2) && fa2 - fb > 0 ? b - fb * (b - a) / (fb - fa2) : 0.5 * (a + b);
        const double mm = (m > a && m < b) ? m : 0.5 * (a + b);
        const double fm = above(o, d, mm);
        if (fm <= 0) {
          b = mm, fb = fm;
          if (side == -1) fa2 *= 0.5;
          side = -1;
        } else {
          a = mm, fa2 = fm;
          if (side == 1) fb *= 0.5;
          side = 1;
        }
      }
      return b;
    }
    s0 = s1, f0 = f1;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

double Caster::solveBilinear(Vec3d o, Vec3d d, double sa, double sb) const {
  // Grid space: x = x0 + s·ex, y = y0 + s·ey, height z = z0 + s·ez.
  const double x0 = ax_ * o.x + bx_, ex = ax_ * d.x, y0 = ay_ * o.z + by_, ey = ay_ * d.z;
  const double z0 = o.y, ez = d.y;
  const HeightField& f = field_;
  const int cellsX = f.width - 1, cellsY = f.height - 1;
  // Clipped to the footprint [0, cellsX] × [0, cellsY] (slabs): beyond it there is no surface, and
  // where the ray enters it below the heights it meets the prism's wall.
  for (const auto& [p0, e, hi] : {std::tuple{x0, ex, double(cellsX)}, std::tuple{y0, ey, double(cellsY)}}) {
    if (e == 0) {
      if (p0 < 0 || p0 > hi) return std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    const double t0 = (0 - p0) / e, t1 = (hi - p0) / e;
    sa = std::max(sa, std::min(t0, t1));
    sb = std::min(sb, std::max(t0, t1));
  }
  if (!(sa <= sb)) return std::numeric_limits<double>::quiet_NaN();
  double s = sa;
  // The cell holding the point at s (the last row and column belong to the cells before them).
  double x = x0 + s * ex, y = y0 + s * ey;
  int i = std::clamp(int(std::floor(x)), 0, cellsX - 1), j = std::clamp(int(std::floor(y)), 0, cellsY - 1);
  const int stepI = ex > 0 ? 1 : -1, stepJ = ey > 0 ? 1 : -1;
  for (int guard = 0; guard < 4 * (cellsX + cellsY) + 8 && s <= sb; ++guard) {
    // Where the ray leaves this cell (or sb).
    const double tx = ex != 0 ? ((ex > 0 ? i + 1 : i) - x0) / ex : kInf;
    const double ty = ey != 0 ? ((ey > 0 ? j + 1 : j) - y0) / ey : kInf;
    const double out = std::min({tx, ty, sb});
    {
      // h = a + b·u + c·v + g·u·v over the cell, u = x − i, v = y − j; along the ray from s:
      // u = u0 + t·ex, v = v0 + t·ey, so z − h = A·t² + B·t + C.
      const double h00 = f.at(i, j), h10 = f.at(i + 1, j), h01 = f.at(i, j + 1),
                   h11 = f.at(i + 1, j + 1);
      // Above the cell's highest corner all the way through it: nothing to solve.
      if (z0 + std::min(s, out) * ez > std::max({h00, h10, h01, h11}) &&
          z0 + out * ez > std::max({h00, h10, h01, h11})) {
        if (out >= sb) break;
        s = out;
        if (tx <= ty) i += stepI;
        if (ty <= tx) j += stepJ;
        if (i < 0 || j < 0 || i >= cellsX || j >= cellsY) break;
        continue;
      }
      const double b = h10 - h00, c = h01 - h00, g = h11 - h10 - h01 + h00;
      const double u0 = x0 + s * ex - i, v0 = y0 + s * ey - j;
      const double A = -g * ex * ey;
      const double B = ez - b * ex - c * ey - g * (u0 * ey + v0 * ex);
      const double C = z0 + s * ez - (h00 + b * u0 + c * v0 + g * u0 * v0);
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
          for (double r : {r1, r2})
            if (r >= 0 && r < root) root = r;
        }
      }
      if (root <= span) return s + root;
    }
    if (out >= sb) break;
    s = out;
    if (tx <= ty) i += stepI;
    if (ty <= tx) j += stepJ;
    if (i < 0 || j < 0 || i >= cellsX || j >= cellsY) break;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

double Caster::cast(Vec3d o, Vec3d d, double s, double s1, CastCounters& c) const {
  ++c.rays;
  const Bundle ray{o, {d, d, d, d}};
  const bool exact = placement_.radius <= 0 && interp_ == Interpolation::bilinear;
  const double speed = gridSpeed(ray);
  if (exact) {
    // A bundle's start lies close to where its rays meet the ground: the first few cells walked
    // directly, before any march (whose steps cost more than a cell's quadratic).
    const double near = std::min(s + kDirectCells / speed, s1);
    ++c.solves;
    const double hit = solveBilinear(o, d, s, near);
    if (!std::isnan(hit)) {
      ++c.hits;
      return hit;
    }
    s = near;
  } else if (above(o, d, s) <= 0) {
    ++c.hits;
    return s;
  }
  while (s < s1) {
    s = march(ray, s, s1, 0, c);
    if (s >= s1) break;
    const double sb = std::min(s + pyramid_.nodeCells(pyramid_.gridLevel() - 1) / speed, s1);
    ++c.solves;
    const double hit = exact ? solveBilinear(o, d, s, sb) : solve(o, d, s, sb, above(o, d, s));
    if (!std::isnan(hit)) {
      ++c.hits;
      return hit;
    }
    s = sb;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

}  // namespace sv::terrain
