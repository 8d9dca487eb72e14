// Method (a)'s plan: a quadtree of display cells, each with its projective map.
// Based on: SPEC §12 (seed 003: distortion correction by transforming the sub-pyramids of the view
// pyramid individually, unit vectors kept in a table and recomputed per frame; the five-point
// projective map); issue 34 item 2. Subdivision until an error bound as in libfive's and SPEC §3's
// recursive subdivision: refine only where the test fails.
//
// Which map (SPEC §12 fixes a map of 3-space by five point pairs): a display fixes only where each
// ray lands — two numbers a ray, and nothing about depth — so the part of the five-point map that
// matters is its action on directions, a homography of the plane of rays (8 degrees of freedom),
// fixed by four rays and their pixels: solveHomography on the corner directions. The depth row is
// then free, and is chosen as glFrustum's with the cell's axis for depth, so that the 4×4 matrix is
// a camera projection; that matrix is the five-point map of 3-space taking three corner points at
// depth znear and one corner at zfar to their clip positions, with a fifth pair to fix the scale
// (tested: SubFrustum.ProjectionIsTheFivePointMapOfItsCorners). Fitting the full 3D map to five
// display pairs would need depths the display does not have.
//
// Symbols: d a direction (homogeneous point of the plane of rays), c = (px, py) a display pixel
// centre, H the cell's homography, (u, v, w) = H·d.
#include "display/subfrustum.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>

#include "core/quadric.h"

namespace sv::display {
namespace {

constexpr double kToDegrees = 180 / std::numbers::pi;

// Valid pixels per rectangle in O(1): counts[(y)(w + 1) + x] = valid pixels in [0, x) × [0, y).
struct ValidCounts {
  int width = 0;
  std::vector<int64_t> counts;
  explicit ValidCounts(const DirectionTable& t) : width(t.width) {
    counts.assign(size_t(t.width + 1) * size_t(t.height + 1), 0);
    for (int y = 0; y < t.height; ++y)
      for (int x = 0; x < t.width; ++x)
        counts[size_t(y + 1) * size_t(width + 1) + size_t(x + 1)] =
            t.valid[t.index(x, y)] + at(x, y + 1) + at(x + 1, y) - at(x, y);
  }
  int64_t at(int x, int y) const { return counts[size_t(y) * size_t(width + 1) + size_t(x)]; }
  int64_t in(int x0, int y0, int x1, int y1) const {
    return at(x1, y1) - at(x0, y1) - at(x1, y0) + at(x0, y0);
  }
};

// Step 1 of a cell: the four pixels to fit on — the corner pixels when valid, otherwise the valid
// pixels extreme along the diagonals (least and greatest x + y and x − y), which are the corners
// when all are valid. False when the cell has no valid pixel.
bool fitPixels(const DirectionTable& t, const SubFrustumCell& c, int px[4], int py[4]) {
  // Keys: x + y (least: top-left; greatest: bottom-right), x − y (greatest: top-right; least:
  // bottom-left). Order: top-left, top-right, bottom-right, bottom-left.
  bool any = false;
  int best[4] = {0, 0, 0, 0};
  for (int y = c.y0; y < c.y1; ++y)
    for (int x = c.x0; x < c.x1; ++x) {
      if (!t.valid[t.index(x, y)]) continue;
      const int key[4] = {-(x + y), x - y, x + y, -(x - y)};
      for (int k = 0; k < 4; ++k)
        if (!any || key[k] > best[k]) {
          best[k] = key[k];
          px[k] = x;
          py[k] = y;
        }
      any = true;
    }
  return any;
}

// Step 2: H from the four pairs, its third row scaled to unit length and facing the directions.
bool fitMapOn(const std::array<Vec3d, 4>& dirs, const std::array<Vec3d, 4>& pixels, Mat3d& h) {
  const Result<Mat3d> fit = solveHomography(dirs, pixels);
  if (!fit.ok()) return false;  // the valid pixels are collinear, or too few
  h = fit.value();
  const Vec3d axis{h.m[2][0], h.m[2][1], h.m[2][2]};
  // r_4 = 1 puts the fourth direction in front (w = 1 > 0), and a cell spans far less than a
  // half-space, so the others are too; the scale makes w the depth along the axis.
  const double s = 1 / std::sqrt(dot(axis, axis));
  for (auto& row : h.m)
    for (double& v : row) v *= s;
  return true;
}

bool fitMap(const DirectionTable& t, const int px[4], const int py[4], Mat3d& h) {
  std::array<Vec3d, 4> dirs, pixels;
  for (size_t k = 0; k < 4; ++k) {
    dirs[k] = t.directions[t.index(px[k], py[k])];
    pixels[k] = {px[k] + 0.5, py[k] + 0.5, 1};
  }
  return fitMapOn(dirs, pixels, h);
}

// The residual of a map at one pixel centre (cx, cy) for the exact direction d there, in pixels
// and radians (measure's two figures).
void residualAt(const Mat3d& map, const Mat3d& inverse, Vec3d d, double cx, double cy,
                double& pixels, double& radians) {
  const Vec3d q = map * d;
  pixels = q.z > 0 ? std::hypot(q.x / q.z - cx, q.y / q.z - cy)
                   : std::numeric_limits<double>::infinity();
  Vec3d m = inverse * Vec3d{cx, cy, 1};
  if (dot(m, Vec3d{map.m[2][0], map.m[2][1], map.m[2][2]}) < 0) m = m * -1;
  radians = angleBetween(d, m);
}

// Step 3: the residuals at every valid pixel centre. With `stopAbove` set, returns as soon as one
// pixel's error exceeds it (the cell will be split: its exact maximum is not needed).
void measure(const DirectionTable& t, SubFrustumCell& c, const Mat3d& inverse,
             std::optional<double> stopAbove) {
  c.residualPixels = c.residualRadians = 0;
  for (int y = c.y0; y < c.y1; ++y)
    for (int x = c.x0; x < c.x1; ++x) {
      const size_t i = t.index(x, y);
      if (!t.valid[i]) continue;
      double pixels, radians;
      residualAt(c.map, inverse, t.directions[i], x + 0.5, y + 0.5, pixels, radians);
      c.residualPixels = std::max(c.residualPixels, pixels);
      c.residualRadians = std::max(c.residualRadians, radians);
      if (stopAbove && !(c.residualPixels <= *stopAbove)) return;
    }
}

SubFrustumCell rectangle(int x0, int y0, int x1, int y1) {
  SubFrustumCell c;
  c.x0 = x0, c.y0 = y0, c.x1 = x1, c.y1 = y1;
  return c;
}

}  // namespace

Mat4d cellProjection(const SubFrustumCell& c, double n, double f) {
  const auto& a = c.map.m[0];
  const auto& b = c.map.m[1];
  const auto& w = c.map.m[2];
  const double sx = 2.0 / (c.x1 - c.x0), sy = 2.0 / (c.y1 - c.y0);
  Mat4d p;
  for (size_t k = 0; k < 3; ++k) {
    // NDC x = sx·(u/w − x0) − 1; NDC y = 1 − sy·(v/w − y0); the w row is the axis.
    p.m[0][k] = sx * a[k] - (sx * c.x0 + 1) * w[k];
    p.m[1][k] = -sy * b[k] + (1 + sy * c.y0) * w[k];
    p.m[2][k] = (f + n) / (f - n) * w[k];
    p.m[3][k] = w[k];
  }
  p.m[0][3] = p.m[1][3] = p.m[3][3] = 0;
  p.m[2][3] = -2 * f * n / (f - n);
  return p;
}

DirectionTable directionTable(const DisplayGeometry& geometry) {
  DirectionTable t;
  t.width = geometry.projector.width;
  t.height = geometry.projector.height;
  viewDirections(geometry, t.directions, t.valid);
  return t;
}

DirectionTable directionTable(const DirectionMap& map) {
  DirectionTable t;
  t.width = map.width;
  t.height = map.height;
  t.valid = map.valid;
  t.directions.reserve(map.directions.size());
  for (const Vec3& d : map.directions) t.directions.push_back(normalize(Vec3d{d.x, d.y, d.z}));
  return t;
}

SubFrustumPlan planSubFrusta(const DirectionTable& display, const SubFrustumOptions& o) {
  SubFrustumPlan plan;
  plan.width = display.width;
  plan.height = display.height;
  const ValidCounts counts(display);
  const int minSize = std::max(o.minCellSize, 2);  // two pixel centres a side to span a map
  // Depth-first, the children pushed in reverse so that cells come out in quadtree order
  // (top-left, top-right, bottom-left, bottom-right).
  std::vector<SubFrustumCell> stack;
  if (display.width > 0 && display.height > 0)
    stack.push_back(rectangle(0, 0, display.width, display.height));
  while (!stack.empty()) {
    SubFrustumCell c = stack.back();
    stack.pop_back();
    c.validPixels = counts.in(c.x0, c.y0, c.x1, c.y1);
    if (c.validPixels == 0) continue;  // wholly invalid: dropped
    const bool splitX = c.x1 - c.x0 >= 2 * minSize, splitY = c.y1 - c.y0 >= 2 * minSize;
    const bool canSplit = splitX || splitY;
    int px[4] = {0, 0, 0, 0}, py[4] = {0, 0, 0, 0};
    std::optional<Mat3d> inverse;
    c.fitted = fitPixels(display, c, px, py) && fitMap(display, px, py, c.map);
    if (c.fitted) inverse = c.map.inverse();
    c.fitted = c.fitted && inverse.has_value();
    if (c.fitted) {
      measure(display, c, *inverse, canSplit ? std::optional<double>(o.boundPixels) : std::nullopt);
      if (!canSplit || c.residualPixels <= o.boundPixels) {
        c.projection = cellProjection(c, o.znear, o.zfar);
        plan.maxResidualPixels = std::max(plan.maxResidualPixels, c.residualPixels);
        plan.maxResidualRadians = std::max(plan.maxResidualRadians, c.residualRadians);
        plan.cellsAboveBound += c.residualPixels > o.boundPixels;
        plan.cells.push_back(c);
        continue;
      }
    } else if (!canSplit) {
      plan.unfittedPixels += c.validPixels;
      plan.cells.push_back(c);
      continue;
    }
    // Step 4: split at the middle, along the sides long enough.
    const int mx = splitX ? c.x0 + (c.x1 - c.x0) / 2 : c.x1;
    const int my = splitY ? c.y0 + (c.y1 - c.y0) / 2 : c.y1;
    const int xs[3] = {c.x0, mx, c.x1}, ys[3] = {c.y0, my, c.y1};
    for (int j = splitY ? 1 : 0; j >= 0; --j)
      for (int i = splitX ? 1 : 0; i >= 0; --i) {
        const int x1 = splitX ? xs[i + 1] : c.x1, y1 = splitY ? ys[j + 1] : c.y1;
        stack.push_back(rectangle(xs[i], ys[j], x1, y1));
      }
  }
  return plan;
}

std::optional<PixelPoint> mapDirection(const SubFrustumCell& cell, Vec3d d) {
  const Vec3d q = cell.map * d;
  if (!(q.z > 0)) return std::nullopt;
  return PixelPoint{q.x / q.z, q.y / q.z};
}

Vec3d mapPixel(const SubFrustumCell& cell, double px, double py) {
  const std::optional<Mat3d> inverse = cell.map.inverse();
  if (!inverse) return {};
  Vec3d m = normalize(*inverse * Vec3d{px, py, 1});
  const Vec3d axis{cell.map.m[2][0], cell.map.m[2][1], cell.map.m[2][2]};
  return dot(m, axis) < 0 ? m * -1 : m;
}

CellFrustum cellFrustum(const SubFrustumCell& cell) {
  // Body axes: −z the cell's axis (the unit third row of H), x the direction in its image plane in
  // which px grows (H's first row less its part along the axis), y = z × x.
  const Vec3d axis{cell.map.m[2][0], cell.map.m[2][1], cell.map.m[2][2]};
  const Vec3d z = axis * -1;
  const Vec3d a{cell.map.m[0][0], cell.map.m[0][1], cell.map.m[0][2]};
  const Vec3d x = normalize(a - axis * dot(a, axis));
  const Vec3d y = cross(z, x);
  Rotation r;
  const Vec3d cols[3] = {x, y, z};
  for (int c = 0; c < 3; ++c) {
    r.m[0][c] = cols[c].x;
    r.m[1][c] = cols[c].y;
    r.m[2][c] = cols[c].z;
  }
  // The tangents of the map's rectangle corners (the map is a homography onto the plane normal to
  // the axis, so the rectangle's image is the quadrilateral of its corners).
  double left = 0, right = 0, down = 0, up = 0;
  const double corners[4][2] = {{double(cell.x0), double(cell.y0)},
                                {double(cell.x1), double(cell.y0)},
                                {double(cell.x1), double(cell.y1)},
                                {double(cell.x0), double(cell.y1)}};
  for (int k = 0; k < 4; ++k) {
    const Vec3d d = mapPixel(cell, corners[k][0], corners[k][1]);
    const double depth = -dot(d, z);
    const double tx = dot(d, x) / depth, ty = dot(d, y) / depth;
    left = k ? std::min(left, tx) : tx;
    right = k ? std::max(right, tx) : tx;
    down = k ? std::min(down, ty) : ty;
    up = k ? std::max(up, ty) : ty;
  }
  // Widened by the residual angle ε: an angle dθ moves a tangent t (the other one s) by at most
  // dθ·(1 + t² + s²)/√(1 + s²) ≤ dθ·(1 + t² + s²), so the exact directions stay inside.
  const double s2 = std::max({left * left, right * right, down * down, up * up});
  const double eps = cell.residualRadians * (1 + 2 * s2) * (1 + 1e-6) + 1e-12;
  CellFrustum f;
  f.orientation = orientationOf(r);
  f.window = {std::atan(left - eps) * kToDegrees, std::atan(right + eps) * kToDegrees,
              std::atan(down - eps) * kToDegrees, std::atan(up + eps) * kToDegrees};
  return f;
}

PlanScreenPoints planScreenPoints(const SubFrustumPlan& plan, const DirectionTable& table,
                                  const DisplayGeometry& geometry) {
  PlanScreenPoints out;
  out.first.reserve(plan.cells.size() + 1);
  const auto add = [&](int x, int y) {
    const double px = x + 0.5, py = y + 0.5;
    const std::optional<Vec3d> p = pixelScreenPoint(geometry, px, py);
    if (p) out.points.push_back({px, py, *p});
  };
  for (const SubFrustumCell& c : plan.cells) {
    out.first.push_back(uint32_t(out.points.size()));
    int px[4], py[4];
    if (!c.fitted || !fitPixels(table, c, px, py)) continue;
    for (int k = 0; k < 4; ++k) add(px[k], py[k]);
    if (out.points.size() - out.first.back() != 4) {  // a fit pixel missed: no refit for it
      out.points.resize(out.first.back());
      continue;
    }
    // The check grid: up to 5 × 5 pixels spread over the cell, its corners and edges included.
    const int w = c.x1 - c.x0, h = c.y1 - c.y0;
    for (int j = 0; j < 5; ++j)
      for (int i = 0; i < 5; ++i) {
        const int x = c.x0 + (w - 1) * i / 4, y = c.y0 + (h - 1) * j / 4;
        if (table.valid[table.index(x, y)]) add(x, y);
      }
  }
  out.first.push_back(uint32_t(out.points.size()));
  return out;
}

namespace {

Vec3d directionFrom(Vec3d eye, Vec3d point) { return normalize(point - eye); }

// Cell c planned again from its own pixels' exact directions for the geometry's eye, its cells
// moved to their place in the display (a map moved by (ox, oy) pixels: H' = T·H).
void replanCell(const SubFrustumCell& c, const DisplayGeometry& g, const SubFrustumOptions& o,
                SubFrustumPlan& out) {
  DirectionTable t;
  t.width = c.x1 - c.x0;
  t.height = c.y1 - c.y0;
  viewDirections(g, c.x0, c.y0, c.x1, c.y1, t.directions, t.valid);
  SubFrustumPlan part = planSubFrusta(t, o);
  for (SubFrustumCell& p : part.cells) {
    p.x0 += c.x0, p.x1 += c.x0, p.y0 += c.y0, p.y1 += c.y0;
    for (size_t k = 0; k < 3; ++k) {
      p.map.m[0][k] += c.x0 * p.map.m[2][k];
      p.map.m[1][k] += c.y0 * p.map.m[2][k];
    }
    if (p.fitted) p.projection = cellProjection(p, o.znear, o.zfar);
    out.cells.push_back(p);
  }
  out.maxResidualPixels = std::max(out.maxResidualPixels, part.maxResidualPixels);
  out.maxResidualRadians = std::max(out.maxResidualRadians, part.maxResidualRadians);
  out.cellsAboveBound += part.cellsAboveBound;
  out.unfittedPixels += part.unfittedPixels;
}

}  // namespace

SubFrustumPlan refitPlan(const SubFrustumPlan& plan, const PlanScreenPoints& points,
                         const DisplayGeometry& g, const SubFrustumOptions& o, RefitStats* stats,
                         core::ThreadPool* pool) {
  const Vec3d eye{g.eye.x, g.eye.y, g.eye.z};
  // Each cell on its own (in parallel), into its own slot — or, planned again, its own plan; the
  // slots joined in cell order.
  const size_t n = plan.cells.size();
  std::vector<SubFrustumCell> refitted(n);
  std::vector<std::unique_ptr<SubFrustumPlan>> replanned(n);
  const auto refitCell = [&](size_t i, int) {
    const SubFrustumCell& old = plan.cells[i];
    const uint32_t first = points.first[i], end = points.first[i + 1];
    if (!old.fitted) {  // too few valid pixels for any map: as it was
      refitted[i] = old;
      return;
    }
    SubFrustumCell c = old;
    bool ok = end - first >= 4;
    std::optional<Mat3d> inverse;
    if (ok) {
      std::array<Vec3d, 4> dirs, pixels;
      for (size_t k = 0; k < 4; ++k) {
        const PlanScreenPoints::Point& p = points.points[first + k];
        dirs[k] = directionFrom(eye, p.screen);
        pixels[k] = {p.px, p.py, 1};
      }
      ok = fitMapOn(dirs, pixels, c.map) && (inverse = c.map.inverse()).has_value();
    }
    if (ok) {
      c.residualPixels = c.residualRadians = 0;
      for (uint32_t k = first + 4; k < end; ++k) {
        const PlanScreenPoints::Point& p = points.points[k];
        double pixels, radians;
        residualAt(c.map, *inverse, directionFrom(eye, p.screen), p.px, p.py, pixels, radians);
        c.residualPixels = std::max(c.residualPixels, pixels);
        c.residualRadians = std::max(c.residualRadians, radians);
      }
      ok = c.residualPixels <= o.boundPixels;
    }
    if (!ok) {
      replanned[i] = std::make_unique<SubFrustumPlan>();
      replanCell(old, g, o, *replanned[i]);
      return;
    }
    c.projection = cellProjection(c, o.znear, o.zfar);
    refitted[i] = c;
  };
  if (pool)
    pool->parallelFor(n, refitCell);
  else
    for (size_t i = 0; i < n; ++i) refitCell(i, 0);
  SubFrustumPlan out;
  out.width = plan.width;
  out.height = plan.height;
  RefitStats st;
  out.cells.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    if (const SubFrustumPlan* part = replanned[i].get()) {
      out.cells.insert(out.cells.end(), part->cells.begin(), part->cells.end());
      out.maxResidualPixels = std::max(out.maxResidualPixels, part->maxResidualPixels);
      out.maxResidualRadians = std::max(out.maxResidualRadians, part->maxResidualRadians);
      out.cellsAboveBound += part->cellsAboveBound;
      out.unfittedPixels += part->unfittedPixels;
      ++st.replanned;
      continue;
    }
    const SubFrustumCell& c = refitted[i];
    out.cells.push_back(c);
    if (!c.fitted) {
      out.unfittedPixels += c.validPixels;
      continue;
    }
    out.maxResidualPixels = std::max(out.maxResidualPixels, c.residualPixels);
    out.maxResidualRadians = std::max(out.maxResidualRadians, c.residualRadians);
    st.maxCheckPixels = std::max(st.maxCheckPixels, c.residualPixels);
    ++st.refitted;
  }
  if (stats) *stats = st;
  return out;
}

}  // namespace sv::display
