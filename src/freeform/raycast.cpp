// Based on: SPEC §12 (seed 003, multi-level ray casting); Keeter 2020 (interval subdivision).
#include "freeform/raycast.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <vector>

#include "core/check.h"

namespace sv::freeform {
namespace {

double windowDepth(double z) { return 0.5 * (z + 1); }

bool inside(double h) { return h >= 0; }

// Step 3 of a pixel: a bracket [a, b] of the ray where H changes sign (inside(fa) ≠ inside(fb)),
// narrowed by Newton's method safeguarded by the bracket (a step that leaves it is replaced by
// the secant point, then by bisection), starting at `guess` when it lies inside (a neighbour's
// hit: the surface is coherent) and stopping when the bracket is below kRootTolerance or the
// Newton point is within it of the root (newtonConverged); returns the last Newton point or, if
// the bracket closed first, its end on the near side of the crossing.
double refineBracket(const RayFunction& f, double a, double b, double fa, double fb,
                     double guess = std::numeric_limits<double>::quiet_NaN()) {
  const bool insideA = inside(fa);
  double z = guess > a && guess < b ? guess : b - fb * (b - a) / (fb - fa);
  if (!(z > a && z < b)) z = 0.5 * (a + b);
  double previous = 0;  // the last Newton step's length (0: none)
  for (int i = 0; i < 60 && b - a > kRootTolerance; ++i) {
    double slope;
    const double fz = f.evaluate(z, slope);
    if (inside(fz) == insideA)
      a = z, fa = fz;
    else
      b = z, fb = fz;
    const double step = slope != 0 ? fz / slope : 0;
    double next = z - step;
    if (newtonConverged(std::fabs(step), previous)) return std::clamp(next, a, b);
    previous = std::fabs(step);
    if (!(next > a && next < b)) {  // safeguarded: no Newton step taken
      next = fb != fa ? b - fb * (b - a) / (fb - fa) : 0.5 * (a + b);
      previous = 0;
    }
    if (!(next > a && next < b)) next = 0.5 * (a + b);
    z = next;
  }
  return a;
}

// Brackets narrower than this (in cube depth) end the binary tree in depth: one with no sign
// change holds an even number of zeros this close together — a ray grazing the surface within
// ~1e-4 of a pixel at 1080p — and is taken as a miss.
constexpr double kBracket = 0x1p-16;

// A ray gives up after splitting this many spans into eight (ProjectedFreeForm::crossingBracket)
// and takes no hit in that range: a degenerate function — zero, or within rounding of zero, along
// a long stretch of the ray — reaches it (tests/render: a quadric that is zero everywhere). A
// plain crossing costs a few splits, but a ray grazing the crease where a perturbation meets its
// base, where H turns within 5e-5 of 0 before it crosses, took ~200 halvings of a binary tree on
// BENCH.md's freeform-one (with 128 it gave up and took the back surface; tests/render:
// RaysGrazingACreaseFindTheFirstCrossing).
constexpr int kSplitBudget = 256;

// A crossing at cube depth z of form `id`, taken where it is nearer than the pixel's depth:
// depth, object and cube depth (those given) written. True if taken.
bool takeHit(double z, uint32_t id, float& depth, uint32_t* object, double* cubeZ,
             CastStats& stats) {
  const float d = float(windowDepth(z));
  if (!(d < depth)) return false;
  ++stats.hits;
  depth = d;
  if (object) *object = id;
  if (cubeZ) *cubeZ = z;
  return true;
}

// One ray's first zero of H in [zlo, zhi] (the root's perturbations `active` holds taken):
// its spans split eight pieces at a time in SIMD lanes (ProjectedFreeForm::crossingBracket, its
// bounds exact per quadric), the bracket refined from `hint` where it lies inside (refineBracket,
// on `ray`, set up here). With a `hint` (a neighbour's hit), the span around it is taken on its
// own, right after the one in front of it: the crossing is likely there. False if there is none
// (or the split budget ran out).
bool firstCrossing(const ProjectedFreeForm& form, double x, double y, uint64_t active, double zlo,
                   double zhi, double hint, RayFunction& ray, double& z, CastStats& stats) {
  double spans[4] = {zlo, zhi};
  int ends = 2;
  if (hint > zlo && hint < zhi) {
    const double d = 1e-4 * (zhi - zlo);
    const double a = std::max(zlo, hint - d), b = std::min(zhi, hint + d);
    ends = 0;
    if (zlo < a) spans[ends++] = zlo;
    spans[ends++] = a;
    spans[ends++] = b;
    if (b < zhi) spans[ends++] = zhi;
  }
  for (int i = 0; i + 1 < ends; ++i) {
    double bracket[4];
    int bounds = 0;
    const bool found = form.crossingBracket(x, y, spans[i], spans[i + 1], active, kBracket,
                                            kSplitBudget, bracket, bounds);
    stats.depthTests += uint64_t(bounds);
    if (!found) continue;
    form.ray(x, y, ray, active);
    z = refineBracket(ray, bracket[0], bracket[1], bracket[2], bracket[3], hint);
    return true;
  }
  return false;
}

// Windows of 2^kRayLevel pixels and less are cast ray by ray.
constexpr int kRayLevel = 2;
// Cells of 2^kQuadricLevel pixels and less that no perturbation reaches are solved ray by ray in
// closed form, without their children's bounds (Caster::cell): 8×8 cells, not 4×4 or 16×16,
// whose empty parts cost more rays than the bounds save (docs/performance.md, "Free forms").
constexpr int kQuadricLevel = 3;
// Rays whose H may turn (Caster::rayWindow) take their spans in this many pieces, the fastest of
// 2, 4, 8 and 16 (docs/performance.md, "Free forms").
constexpr int kPieces = 8;

class Caster {
 public:
  Caster(const ProjectedFreeForm& form, uint32_t id, const CastWindow& w, const CastSettings& s,
         MaskingPyramid& pyramid, CastStats& stats)
      : form_(form), id_(id), w_(w), settings_(s), pyramid_(pyramid), stats_(stats) {
    // The rays' cube x of every column and y of every row of the window, worked out once (a
    // division each; the cells and ray windows read them many times over).
    columns_.resize(size_t(std::max(w.size, 0)));
    rows_.resize(columns_.size());
    for (int i = 0; i < w.size; ++i) {
      columns_[size_t(i)] = cubeX(w.x0 + i, w.width, w.offsetX);
      rows_[size_t(i)] = cubeY(w.y0 + i, w.height, w.offsetY);
    }
  }

  // Casts the form; returns the perturbations that may be positive anywhere in the window (all
  // where the whole window was never bounded).
  uint64_t run() {
    cell(pyramid_.top(), 0, 0, -1, 1, kAllActive);
    return windowActive_;
  }

 private:
  float& node(int level, int x, int y) { return pyramid_.node(level, x, y); }

  // The window of 2^level pixels at (lx, ly) (window-local), its cells in depth [zlo, zhi];
  // `active`: the form's perturbations that may be positive there (ProjectedFreeForm::bound) —
  // the others are left out of its bounds and rays.
  // `given`: the window's bound (value, slope and perturbations that may be positive) where its
  // parent worked it out with its siblings' (boundWindows), for windows cast ray by ray.
  struct WindowBound {
    Interval value, slope;
    uint64_t active;
  };
  // The window of 2^level pixels at (lx, ly): its raster pixels [gx0, gx1] × [gy0, gy1] (empty
  // off the raster) and the cube box of their rays.
  struct Box {
    int gx0, gy0, gx1, gy1;
    Interval x, y;
    bool empty() const { return gx0 > gx1 || gy0 > gy1; }
  };
  Box boxOf(int level, int lx, int ly) const {
    Box b;
    b.gx0 = w_.x0 + lx, b.gy0 = w_.y0 + ly;
    b.gx1 = std::min(b.gx0 + (1 << level), w_.width) - 1;
    b.gy1 = std::min(b.gy0 + (1 << level), w_.height) - 1;
    b.x = {columns_[size_t(lx)], columns_[size_t(b.gx1 - w_.x0)]};
    b.y = {rows_[size_t(b.gy1 - w_.y0)], rows_[size_t(ly)]};
    return b;
  }

  void cell(int level, int lx, int ly, double zlo, double zhi, uint64_t active,
            const WindowBound* given = nullptr) {
    const int n = 1 << level;
    const Box box = boxOf(level, lx, ly);
    if (box.empty()) return;
    const int gx0 = box.gx0, gy0 = box.gy0, gx1 = box.gx1, gy1 = box.gy1;
    ++stats_.cells;
    // Step 1: multi-level masking — every pixel already holds a nearer surface.
    if (settings_.masking && windowDepth(zlo) >= double(node(level, lx >> level, ly >> level))) {
      ++stats_.maskedCells;
      return;
    }
    const Interval x = box.x, y = box.y;
    // Small windows: every pixel's own ray (RayFunction) is cheaper than bounding the window's
    // 2×2 and 1×1 subwindows in x, y and z (measured: levels 1 and 2 were 2.5 of the ~2.7 window
    // bounds per pixel on BENCH.md's freeform).
    if (level <= kRayLevel) {
      // A window where ∂H/∂z keeps its sign meets each of its rays at most once: the ends of
      // each ray's span decide, and the crossing is refined directly.
      WindowBound b{{}, {}, active};  // of those, the ones that may be positive in the window
      ++stats_.depthTests;
      if (given)
        b = *given;
      else
        form_.bound(x, y, {zlo, zhi}, b.value, b.slope, &b.active);
      if (!b.value.containsZero()) return;
      // The rays read their own pixels' depths, never the masking pyramid: a hit writes its
      // pixel's node, and the window's ancestors are brought up to date once, after its rays.
      if (rayWindow(lx, ly, n, gx0, gy0, gx1, gy1, zlo, zhi, !b.slope.containsZero(), b.active))
        refreshAbove(level, lx, ly);
      return;
    }
    // A cell no perturbation reaches (its parent's bounds said so) is solved whole, without its
    // own bounds: most such cells hold the surface (measured on BENCH.md's freeform: 15 % of
    // them empty), and the solution needs no depth range tighter than [zlo, zhi].
    if (level <= kQuadricLevel && form_.quadricsAlone(active))
      return quadricCell(level, lx, ly, box, zlo, zhi, active);
    // Step 2: the binary tree in depth, four levels deep: of sixteen slabs (the fastest of 4, 8,
    // 16 and 32, docs/performance.md "Free forms"), those whose bound may hold the surface.
    // Runs of such slabs are separate depth ranges — a solid's front and back surfaces, with its
    // inside (H > 0 throughout) between them — taken front to back, so that once the front one
    // has filled the window, masking drops the back one whole.
    constexpr int kSlabs = 16;
    bool holds[kSlabs];
    stats_.depthTests += kSlabs;
    uint64_t positive;  // the perturbations that may be positive in the cell: its children's
    form_.slabsHolding(x, y, zlo, zhi, kSlabs, holds, active, &positive);
    if (level == pyramid_.top()) windowActive_ = positive;
    if (level <= kQuadricLevel && form_.quadricsAlone(positive)) {
      // No perturbation reaches the cell: solved whole over the slabs from the first that may
      // hold the surface to the last (those between hold no crossing).
      int first = 0, last = kSlabs - 1;
      while (first < kSlabs && !holds[first]) ++first;
      if (first == kSlabs) return;
      while (!holds[last]) --last;
      return quadricCell(level, lx, ly, box, zlo + (zhi - zlo) * first / kSlabs,
                         last == kSlabs - 1 ? zhi : zlo + (zhi - zlo) * (last + 1) / kSlabs,
                         positive);
    }
    const int h = n / 2;
    for (int s = 0; s < kSlabs;) {
      if (!holds[s]) {
        ++s;
        continue;
      }
      int e = s + 1;
      while (e < kSlabs && holds[e]) ++e;
      const double nlo = zlo + (zhi - zlo) * s / kSlabs;
      const double nhi = e == kSlabs ? zhi : zlo + (zhi - zlo) * e / kSlabs;
      // Step 3: the four children, in this range — the bounds of those cast ray by ray worked
      // out together, a window per SIMD lane.
      WindowBound bounds[4];
      if (level - 1 == kRayLevel) {
        Interval cx[4], cy[4], value[4], slope[4];
        uint64_t positives[4];
        for (int c = 0; c < 4; ++c) {  // children off the raster are never read
          const Box child = boxOf(level - 1, lx + (c & 1) * h, ly + (c >> 1) * h);
          cx[c] = child.x;
          cy[c] = child.y;
        }
        form_.boundWindows(cx, cy, 4, {nlo, nhi}, positive, value, slope, positives);
        for (int c = 0; c < 4; ++c) bounds[c] = {value[c], slope[c], positives[c]};
      }
      for (int c = 0; c < 4; ++c)
        cell(level - 1, lx + (c & 1) * h, ly + (c >> 1) * h, nlo, nhi, positive,
             level - 1 == kRayLevel ? &bounds[c] : nullptr);
      s = e;
    }
  }

  // A cell no perturbation reaches (`active` holds none): its rays solved in closed form, all at
  // once (quadricCrossings), over [zlo, zhi] — without its children's bounds.
  void quadricCell(int level, int lx, int ly, const Box& box, double zlo, double zhi,
                   uint64_t active) {
    const int n = 1 << level;
    if (n == 8 && box.gx1 - box.gx0 == 7 && box.gy1 - box.gy0 == 7) {
      // A whole 8×8 cell: solved and taken a row at a time in SIMD lanes (quadricHits), the
      // rays' set-up and hits included.
      HitRows to;
      const size_t at = size_t(ly) * size_t(w_.stride) + size_t(lx);
      to.depth = w_.depth + at;
      to.object = w_.object ? w_.object + at : nullptr;
      to.cubeZ = w_.cubeZ ? w_.cubeZ + at : nullptr;
      to.active = w_.active ? w_.active + at : nullptr;
      to.stride = size_t(w_.stride);
      to.node = &node(0, lx, ly);
      to.nodeStride = size_t(pyramid_.size());
      to.id = id_;
      to.activeBits = active;
      stats_.pixels += 64;
      const int hits =
          form_.quadricHits(columns_.data() + lx, rows_.data() + ly, zlo, zhi, to, guess_);
      stats_.hits += uint64_t(hits);
      if (hits > 0) refreshAbove(level, lx, ly);
      return;
    }
    const int count = windowRays(lx, ly, n, box.gx0, box.gy0, box.gx1, box.gy1, zhi);
    form_.quadricCrossings(lanes_.x, lanes_.y, zlo, lanes_.end, count, lanes_.z);
    if (takeHits(lx, ly, n, box.gx0, box.gy0, box.gx1, box.gy1, active))
      refreshAbove(level, lx, ly);
  }

  // The rays of the window of n × n pixels at (lx, ly), raster pixels [gx0, gx1] × [gy0, gy1],
  // into lanes_ row by row: where each begins in the tile (at), its cube x and y, and the end of
  // its span — zhi, or the depth its pixel already holds if nearer. Returns how many.
  int windowRays(int lx, int ly, int n, int gx0, int gy0, int gx1, int gy1, double zhi) {
    const double* const columns = columns_.data() + lx;
    const double* const rows = rows_.data() + ly;
    int count = 0;
    for (int py = 0; py < n && gy0 + py <= gy1; ++py)
      for (int px = 0; px < n && gx0 + px <= gx1; ++px, ++count) {
        const size_t at = size_t(ly + py) * size_t(w_.stride) + size_t(lx + px);
        lanes_.at[count] = at;
        lanes_.x[count] = columns[px];
        lanes_.y[count] = rows[py];
        lanes_.end[count] = std::min(zhi, 2.0 * double(w_.depth[at]) - 1);
      }
    stats_.pixels += uint64_t(count);
    return count;
  }

  // The crossings lanes_.z of windowRays' rays taken where nearer, `active` kept with each (the
  // perturbations that may be positive in the window). True if any pixel took a hit.
  bool takeHits(int lx, int ly, int n, int gx0, int gy0, int gx1, int gy1, uint64_t active) {
    const double* const z = lanes_.z;
    bool hits = false;
    for (int i = 0, py = 0; py < n && gy0 + py <= gy1; ++py)
      for (int px = 0; px < n && gx0 + px <= gx1; ++px, ++i)
        if (!std::isnan(z[i]) && hit(lx + px, ly + py, lanes_.at[i], z[i], active)) {
          hits = true;
          guess_ = z[i];
        }
    return hits;
  }

  // The rays of a window of n × n pixels (n ≤ 4) at (lx, ly), raster pixels [gx0, gx1] ×
  // [gy0, gy1], over [zlo, zhi], solved together. Where no perturbation reaches the window, in
  // closed form (quadricCrossings); else by Newton, starting from neighbours' hits or the last
  // hit of this form in the tile (the surface is coherent). `monotonic`: the window's slope bound
  // says each ray crosses at most once (ProjectedFreeForm::monotonicCrossings); otherwise —
  // silhouettes, mostly — turningCrossings. True if any pixel took a hit.
  bool rayWindow(int lx, int ly, int n, int gx0, int gy0, int gx1, int gy1, double zlo, double zhi,
                 bool monotonic, uint64_t active) {
    const int count = windowRays(lx, ly, n, gx0, gy0, gx1, gy1, zhi);
    const double* const x = lanes_.x;
    const double* const y = lanes_.y;
    const double* const end = lanes_.end;
    double* const guess = lanes_.guess;
    double* const z = lanes_.z;
    if (form_.quadricsAlone(active)) {
      // No perturbation reaches the window: H along each ray is the root's quadratic (and the
      // clips'), solved in closed form — no guess, no bound, whatever the slope.
      form_.quadricCrossings(x, y, zlo, end, count, z);
    } else {
      // Where Newton starts: the surface is coherent, so from this form's hits in the pixels
      // just left of the ray's row or above its column — the nearer — extrapolated linearly from
      // the next pixel out where that holds one too; else from the form's last hit in the tile.
      Neighbours left[4], above[4];
      for (int p = 0; p < n; ++p) {
        left[p] = neighbours(lx - 1, ly + p, -1, 0);
        above[p] = neighbours(lx + p, ly - 1, 0, -1);
      }
      bool near[16];  // the guess is a neighbour's hit (not only the tile's last one)
      for (int i = 0, py = 0; py < n && gy0 + py <= gy1; ++py)
        for (int px = 0; px < n && gx0 + px <= gx1; ++px, ++i) {
          const Neighbours& first = px <= py ? left[py] : above[px];
          const Neighbours& second = px <= py ? above[px] : left[py];
          near[i] = first.hits > 0 || second.hits > 0;
          guess[i] = first.hits > 0    ? first.guess(px <= py ? px + 1 : py + 1)
                     : second.hits > 0 ? second.guess(px <= py ? py + 1 : px + 1)
                                       : guess_;
        }
      if (monotonic)
        form_.monotonicCrossings(x, y, zlo, end, count, guess, z, active);
      else
        turningCrossings(zlo, count, near, active);
    }
    return takeHits(lx, ly, n, gx0, gy0, gx1, gy1, active);
  }

  // rayWindow's rays (lanes_, the first `count`) where H may turn. Most such windows lie wholly
  // on the surface, their slope bound only loose over the run of slabs: rays with a neighbour's
  // hit (`near`) first try Newton from it, a zero kept where the ray's own bound proves it the
  // first (provenCrossings); the others are taken in pieces, and a ray whose H may turn within a
  // piece goes on alone from there.
  void turningCrossings(double zlo, int count, const bool* near, uint64_t active) {
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    const double* const x = lanes_.x;
    const double* const y = lanes_.y;
    const double* const end = lanes_.end;
    const double* const guess = lanes_.guess;
    double* const z = lanes_.z;
    double* const from = lanes_.from;
    double tried[16];
    for (int i = 0; i < count; ++i) tried[i] = near[i] ? guess[i] : kNaN;
    stats_.depthTests += uint64_t(form_.provenCrossings(x, y, zlo, end, count, tried, z, active));
    // The rays left, packed (their indices in `place`), in pieces.
    double px[16], py[16], pend[16], pguess[16], pz[16];
    int place[16], rest = 0;
    for (int i = 0; i < count; ++i)
      if (std::isnan(z[i])) {
        place[rest] = i;
        px[rest] = x[i], py[rest] = y[i], pend[rest] = end[i], pguess[rest] = guess[i];
        ++rest;
      }
    if (rest > 0)
      stats_.depthTests += uint64_t(
          form_.piecewiseCrossings(px, py, zlo, pend, rest, kPieces, pguess, pz, from, active));
    for (int j = 0; j < rest; ++j) {
      const int i = place[j];
      z[i] = pz[j];
      if (std::isnan(from[j])) continue;
      // The ray's own subdivision, eight pieces at a time rather than halves one at a time
      // (docs/performance.md, "Free forms").
      if (!firstCrossing(form_, x[i], y[i], active, from[j], end[i], kNaN, ray_, z[i], stats_))
        z[i] = kNaN;
    }
  }

  // This form's hits at the pixel (qx, qy) and the next one out, (qx + dx, qy + dy): how many
  // of the two in a row (0, 1 or 2) and their cube depths.
  struct Neighbours {
    int hits = 0;
    double z1 = 0, z2 = 0;
    // The depth extrapolated `steps` pixels on from the first.
    double guess(int steps) const { return hits == 2 ? z1 + (z1 - z2) * steps : z1; }
  };
  Neighbours neighbours(int qx, int qy, int dx, int dy) const {
    Neighbours nb;
    const auto hitAt = [&](int px, int py, double& z) {
      if (px < 0 || py < 0 || !w_.object || !w_.cubeZ) return false;
      const size_t k = size_t(py) * size_t(w_.stride) + size_t(px);
      if (w_.object[k] != id_) return false;
      z = w_.cubeZ[k];
      return true;
    };
    if (hitAt(qx, qy, nb.z1)) nb.hits = hitAt(qx + dx, qy + dy, nb.z2) ? 2 : 1;
    return nb;
  }

  // Takes the hit where it is nearer; the pixel's node follows (its ancestors: refreshAbove).
  // `active`: the perturbations that may be positive in the window of the hit (CastWindow's).
  bool hit(int lx, int ly, size_t at, double z, uint64_t active) {
    if (!takeHit(z, id_, w_.depth[at], w_.object ? w_.object + at : nullptr,
                 w_.cubeZ ? w_.cubeZ + at : nullptr, stats_))
      return false;
    node(0, lx, ly) = w_.depth[at];
    if (w_.active) w_.active[at] = active;
    return true;
  }

  void refreshAbove(int level, int lx, int ly) { pyramid_.refreshAbove(level, lx, ly); }

  const ProjectedFreeForm& form_;
  uint32_t id_;
  const CastWindow& w_;
  const CastSettings& settings_;
  MaskingPyramid& pyramid_;
  CastStats& stats_;
  uint64_t windowActive_ = kAllActive;  // run()'s
  RayFunction ray_;                     // the current pixel's
  // windowRays' rays (only the first `count` of each are read): up to a cell of
  // 2^kQuadricLevel pixels square; guess and from, rayWindow's only.
  static constexpr int kMaxRays = 1 << (2 * kQuadricLevel);
  struct {
    double x[kMaxRays], y[kMaxRays], end[kMaxRays], z[kMaxRays], guess[16], from[16];
    size_t at[kMaxRays];
  } lanes_;
  double guess_ = std::numeric_limits<double>::quiet_NaN();  // the last hit (monotonicWindow)
  std::vector<double> columns_, rows_;  // the rays' cube x, y per column and row
};

}  // namespace

MaskingPyramid::MaskingPyramid(const CastWindow& w) : size_(w.size) {
  constexpr int kTileRow = 64;  // the tile pass's windows
  top_ = std::countr_zero(unsigned(w.size));
  offset_.resize(size_t(top_) + 1);
  size_t total = 0;
  for (int l = 0; l <= top_; ++l) {
    offset_[size_t(l)] = total;
    total += size_t(1) << (2 * (top_ - l));
  }
  nodes_.resize(total);
  // Level 0: the depths, row by row; pixels beyond the raster hold −∞ (they never need a
  // surface).
  const int columns = std::clamp(w.width - w.x0, 0, w.size);
  for (int y = 0; y < w.size; ++y) {
    float* row = &node(0, 0, y);
    const int inside = w.y0 + y < w.height ? columns : 0;
    const float* depth = w.depth + size_t(y) * size_t(w.stride);
    if (inside == kTileRow && w.size == kTileRow) {  // the common row, copied inline
      std::copy_n(depth, kTileRow, row);
      continue;
    }
    std::copy_n(depth, inside, row);
    std::fill(row + inside, row + w.size, -std::numeric_limits<float>::infinity());
  }
  for (int l = 1; l <= top_; ++l)
    for (int y = 0; y < (w.size >> l); ++y)
      for (int x = 0; x < (w.size >> l); ++x) update(l, x, y);
}

void MaskingPyramid::update(int l, int x, int y) {
  node(l, x, y) =
      std::max(std::max(node(l - 1, 2 * x, 2 * y), node(l - 1, 2 * x + 1, 2 * y)),
               std::max(node(l - 1, 2 * x, 2 * y + 1), node(l - 1, 2 * x + 1, 2 * y + 1)));
}

void MaskingPyramid::refreshAbove(int level, int lx, int ly) {
  int l = 1;
  if (level == 2 && top_ >= 2 && (lx & 3) == 0 && (ly & 3) == 0) {
    // A ray window of 4×4 (every hit's): its four 2×2 nodes and its own straight from its 16
    // pixels' rows, without update's index arithmetic for each.
    const size_t width0 = size_t(size_), width1 = width0 / 2;
    const float* p = nodes_.data() + size_t(ly) * width0 + size_t(lx);
    float* q = nodes_.data() + offset_[1] + size_t(ly / 2) * width1 + size_t(lx / 2);
    float m[2][2];
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 2; ++x) {
        const float* a = p + size_t(2 * y) * width0 + size_t(2 * x);
        m[y][x] = std::max(std::max(a[0], a[1]), std::max(a[width0], a[width0 + 1]));
        q[size_t(y) * width1 + size_t(x)] = m[y][x];
      }
    node(2, lx >> 2, ly >> 2) = std::max(std::max(m[0][0], m[0][1]), std::max(m[1][0], m[1][1]));
    l = 3;
  }
  for (; l <= top_; ++l) {
    const int span = l <= level ? 1 << (level - l) : 1;
    for (int y = 0; y < span; ++y)
      for (int x = 0; x < span; ++x) update(l, (lx >> l) + x, (ly >> l) + y);
  }
}

void castWindow(const ProjectedFreeForm& form, uint32_t id, const CastWindow& window,
                const CastSettings& settings, CastStats& stats, MaskingPyramid* pyramid,
                uint64_t* active) {
  SV_CHECK(window.size >= 1 && window.size <= 64 && std::has_single_bit(unsigned(window.size)));
  // Counted locally: the callers' per-thread totals may share a cache line, and counting into
  // them directly made one line bounce between the cores on every bound (2/3 of a frame).
  CastStats local;
  uint64_t positive;
  if (pyramid) {
    positive = Caster(form, id, window, settings, *pyramid, local).run();
  } else {
    MaskingPyramid own(window);
    positive = Caster(form, id, window, settings, own, local).run();
  }
  if (active) *active = positive;
  stats.add(local);
}

void castRay(const ProjectedFreeForm& form, uint32_t id, double x, double y, double from,
             double hint, float& depth, uint32_t& object, double& cubeZ, RayFunction& ray,
             CastStats& stats) {
  ++stats.pixels;
  const double zlo = std::max(-1.0, from), zhi = std::min(1.0, 2.0 * double(depth) - 1);
  if (!(zlo < zhi)) return;
  // The ray's own bound over its span: none of it may hold the surface, or only some of the
  // perturbations may be positive along it (the others are 0 there) — where none, H is its
  // quadrics alone, solved in closed form.
  Interval value, slope;
  uint64_t active = kAllActive;
  ++stats.depthTests;
  form.bound({x, x}, {y, y}, {zlo, zhi}, value, slope, &active);
  if (!value.containsZero()) return;
  double z;
  if (form.quadricsAlone(active)) {
    form.quadricCrossings(&x, &y, zlo, &zhi, 1, &z);
    if (!std::isnan(z)) takeHit(z, id, depth, &object, &cubeZ, stats);
    return;
  }
  if (firstCrossing(form, x, y, active, zlo, zhi, hint, ray, z, stats))
    takeHit(z, id, depth, &object, &cubeZ, stats);
}

void marchWindow(const ProjectedFreeForm& form, uint32_t id, const CastWindow& window, int steps,
                 CastStats& total) {
  CastStats stats;  // local, as castWindow's
  RayFunction ray;
  for (int ly = 0; ly < window.size && window.y0 + ly < window.height; ++ly)
    for (int lx = 0; lx < window.size && window.x0 + lx < window.width; ++lx) {
      ++stats.pixels;
      const size_t at = size_t(ly) * size_t(window.stride) + size_t(lx);
      const double x = cubeX(window.x0 + lx, window.width, window.offsetX);
      const double y = cubeY(window.y0 + ly, window.height, window.offsetY);
      const double zEnd = std::min(1.0, 2.0 * double(window.depth[at]) - 1);
      form.ray(x, y, ray);
      const double tNear = ray.eyeDepth(-1), tFar = ray.eyeDepth(1);
      double a = -1, fa = ray.evaluate(a);
      for (int i = 1; i <= steps && a < zEnd; ++i) {
        const double b =
            std::min(zEnd, i == steps ? 1.0 : ray.cubeDepth(tNear + (tFar - tNear) * i / steps));
        const double fb = ray.evaluate(b);
        if (inside(fb) != inside(fa)) {
          takeHit(refineBracket(ray, a, b, fa, fb), id, window.depth[at],
                  window.object ? window.object + at : nullptr,
                  window.cubeZ ? window.cubeZ + at : nullptr, stats);
          break;
        }
        a = b, fa = fb;
      }
    }
  total.add(stats);
}

}  // namespace sv::freeform
