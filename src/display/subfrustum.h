// Distortion correction the seeds' way (SPEC §12, issue 34 item 2, "method (a)"): the plan — a
// display's pixel rectangle split into cells, each with the projective map that takes the eye's
// view directions to the cell's display pixels, refined until the map's error is below a bound.
// Rendering through the maps (each cell as a camera whose projection is its map, no resampling)
// is a later stage's; this is the geometry.
//
// Conventions are geometry.h's: directions in the eye frame from the display's eye, pixels
// continuous with centres at +0.5, rows top first.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "core/projective.h"
#include "core/thread_pool.h"
#include "display/geometry.h"

namespace sv::display {

// A display mapping in double: the unit direction each pixel centre shows, rows top first, and
// whether it shows one (an invalid pixel's direction is zero). The plan's residuals are measured
// against these, so their precision bounds what a residual can tell: float directions
// (DirectionMap, MPCDI warps) carry 6e-8 rad of rounding.
struct DirectionTable {
  int width = 0, height = 0;
  std::vector<Vec3d> directions;
  std::vector<uint8_t> valid;
  size_t index(int x, int y) const { return size_t(y) * size_t(width) + size_t(x); }
};
DirectionTable directionTable(const DisplayGeometry& geometry);  // analytic, in double
DirectionTable directionTable(const DirectionMap& map);          // widened from float

struct SubFrustumOptions {
  double boundPixels = 0.1;          // the residual a cell must reach, display pixels
  int minCellSize = 4;               // cells are not split below this many pixels a side
  double znear = 0.1, zfar = 10000;  // the depth range of each cell's projection, metres
};

// One cell: the display pixels [x0, x1) × [y0, y1) and its map.
struct SubFrustumCell {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  // The homography H of the cell: a direction d (eye frame, homogeneous) shows at display pixel
  // (u/w, v/w) for (u, v, w) = H·d, w > 0 in front. Its third row has unit length, so w is the
  // depth of d along the cell's axis (the normal of its image plane).
  Mat3d map;
  // The same map as a camera's projection for this rectangle, acting on eye-frame points relative
  // to the display's eye, (p − eye, 1): clip x/w runs from −1 at x0 to +1 at x1, y/w from +1 at y0
  // to −1 at y1 (clip y up, as glFrustum's), and z/w from −1 at depth znear to +1 at zfar along
  // the cell's axis (glFrustum's depth row with w = that depth).
  Mat4d projection;
  double residualPixels = 0;   // max over the cell's valid pixel centres, see planSubFrusta
  double residualRadians = 0;  // likewise, as an angle
  int64_t validPixels = 0;
  bool fitted = true;  // false: fewer than four valid pixels with no three collinear
};

struct SubFrustumPlan {
  int width = 0, height = 0;
  std::vector<SubFrustumCell> cells;                     // in quadtree order
  double maxResidualPixels = 0, maxResidualRadians = 0;  // over the fitted cells
  int cellsAboveBound = 0;     // fitted cells at the minimum size still above the bound
  int64_t unfittedPixels = 0;  // valid pixels in cells without a map
};

// The plan (SPEC §12: "the sub-pyramids are transformed individually"): starting from the whole
// display, a cell's map is fitted on four of its valid pixel centres — its corner pixels when they
// are valid, otherwise the valid pixels extreme along the two diagonals — and its residual
// measured at every valid pixel centre of the cell: in pixels, |H·d − c| for the exact direction d
// of the pixel centre c (where the map puts what the pixel should show); in radians, the angle
// between d and H⁻¹·c (what the map shows at the pixel instead). A cell above `boundPixels` is
// split at its middle (in x and y, or only along a side of at least 2·minCellSize) while it can
// be; a wholly invalid cell is dropped. Cells tile the display: every valid pixel centre lies in
// exactly one cell, and no cell holds only invalid pixels.
SubFrustumPlan planSubFrusta(const DirectionTable& display, const SubFrustumOptions& options = {});

// Dynamic correction (SPEC §12: the maps "recomputed per frame for dynamic correction (moving eye
// and projector)"; issue 61): the cells of a plan stay, and a moved eye refits their maps. What of
// a plan does not depend on the eye — the pixel centres each fitted cell's map is fitted on (its
// four fit pixels) and checked at (a grid of up to 5 × 5 of its valid pixels), and the screen
// points they light — kept once.
struct PlanScreenPoints {
  struct Point {
    double px = 0, py = 0;  // a pixel centre
    Vec3d screen;           // the screen point it lights
  };
  std::vector<Point> points;    // per cell: its four fit points, then its check points
  std::vector<uint32_t> first;  // per cell, and one past the last: where its points start
};
// From a plan of `geometry`'s direction table (`table`, for the valid mask) — analytic displays
// only: an MPCDI file's directions have no screen points.
PlanScreenPoints planScreenPoints(const SubFrustumPlan& plan, const DirectionTable& table,
                                  const DisplayGeometry& geometry);

struct RefitStats {
  int refitted = 0;   // cells whose new map passed its check
  int replanned = 0;  // cells planned again from their pixels' exact directions (then split)
  double maxCheckPixels = 0;  // the largest residual at the refitted cells' check points
};
// The plan of `geometry` for its eye (geometry.eye), from `plan` (made for another eye of the same
// projector and screen) and its screen points: each fitted cell's map fitted again on its four fit
// points seen from the new eye; a cell whose check points then err by more than 0.8 × the bound
// is planned again from the exact directions of its own pixels (and split as planSubFrusta
// would). No per-pixel work for the cells that pass: ~1 µs a cell.
// In parallel on `pool` when given (the same plan for any thread count).
SubFrustumPlan refitPlan(const SubFrustumPlan& plan, const PlanScreenPoints& points,
                         const DisplayGeometry& geometry, const SubFrustumOptions& options = {},
                         RefitStats* stats = nullptr, core::ThreadPool* pool = nullptr);

// SubFrustumCell::projection of a fitted cell for the depth range [znear, zfar] (glFrustum's depth
// row with the cell's axis depth): a camera's own range, where it differs from the plan's.
Mat4d cellProjection(const SubFrustumCell& cell, double znear, double zfar);

// Where direction d shows under a cell's map (continuous display pixel), or nothing behind it.
struct PixelPoint {
  double x, y;
};
std::optional<PixelPoint> mapDirection(const SubFrustumCell& cell, Vec3d d);
// The unit direction the map shows at display pixel (px, py).
Vec3d mapPixel(const SubFrustumCell& cell, double px, double py);

// An asymmetric frustum (channelCamera's orientation + window) that covers a fitted cell:
// looking along the cell's axis, x along its rows, its window the tangent box of the map's
// rectangle corners widened by the cell's angular residual — so it holds both what the map draws
// and the exact directions of the cell's pixels. (A homography has one degree of freedom more than
// such a camera — skew — so the cell is drawn with `projection`, and the frustum serves culling.)
struct CellFrustum {
  Orientation orientation;
  Window window;
};
CellFrustum cellFrustum(const SubFrustumCell& cell);

}  // namespace sv::display
