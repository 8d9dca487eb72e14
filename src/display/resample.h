// Distortion correction by resampling (issue 34 item 3, "method (b)", the industry's way): render
// the channel flat through a pinhole camera with a margin, then give each display pixel the flat
// image's value in the direction that pixel shows, interpolated bilinearly or bicubically. The
// comparison for the seeds' method (SPEC §12 sub-frusta, display/subfrustum.h), which draws the
// geometry pre-distorted and resamples nothing.
//
// Conventions are geometry.h's: directions in the eye frame, orientations and windows as a
// channel's, pixels continuous with centres at +0.5, rows top first.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "display/geometry.h"
#include "synthvis/result.h"

namespace sv::display {

// A flat (pinhole) camera's frustum and pixels: the camera looks along `orientation` (rotationOf)
// from the eye; flat pixel (fx, fy) shows the direction whose body coordinates are
// (tan l + (fx/W)·(tan r − tan l), tan u − (fy/H)·(tan u − tan d), −1) — a Projector's lens
// convention, and channelCamera's image of a channel with this orientation and window.
struct FlatView {
  Orientation orientation;
  Window window;
  int width = 0, height = 0;
};

// Where `direction` (eye frame, any length: only its line through the eye matters) lands in the
// flat image, as continuous pixel coordinates — or nothing when it points behind the camera
// (or sideways, at its horizon).
struct FlatPoint {
  double x, y;
};
std::optional<FlatPoint> flatPointOf(const FlatView& view, Vec3 direction);

// Catmull–Rom is Keys's cubic convolution with a = −1/2 (Keys 1981, "Cubic convolution
// interpolation for digital image processing"): it interpolates, and reproduces polynomials up to
// degree 2 exactly.
enum class ResampleFilter : uint8_t { bilinear, bicubic };

struct ResampledImage {
  int width = 0, height = 0;
  std::vector<uint16_t> rgb;  // 3 values a pixel, rows top first, linear light
  int64_t outside = 0;        // valid display pixels whose direction misses the flat image: black
  int64_t invalid = 0;        // display pixels with no direction (the map's invalid ones): black
};

// The warp of method (b) — a simulator's warp map: where each display pixel's direction lands in
// the flat image (flatPointOf), worked out once per display mapping and flat view, then read by
// every frame's resampling. A valid pixel lands when its point lies inside the flat image's
// rectangle [0, W] × [0, H]; other valid pixels are `outside`, pixels without a direction
// `invalid`. Directions need not be unit length.
struct ResampleWarp {
  FlatView view;
  int width = 0, height = 0;  // the display's
  // Two floats a display pixel, rows top first: the flat point's x and y, or NaN where the pixel
  // does not land (then black).
  std::vector<float> points;
  int64_t outside = 0, invalid = 0;
  bool lands(size_t pixel) const { return points[2 * pixel] == points[2 * pixel]; }
};
ResampleWarp resampleWarp(const FlatView& view, const DirectionMap& display);

// Rows [y0, y1) of the display image through `warp` from a flat image (linear-light 16-bit RGB,
// 3 values a pixel, rows top first, warp.view's size) into `rgb` (the whole display image's
// buffer, the same layout): a landing pixel gets the filtered value at its point — flat samples
// beyond the image's edge repeat its edge (clamp to edge), so a margin of 2 flat pixels keeps the
// bicubic footprint inside — rounded to the nearest code and clamped to 0 … 65535 (the cubic
// overshoots at edges); the others black. Row bands may run in parallel.
void resampleRows(const ResampleWarp& warp, const uint16_t* flatRgb, ResampleFilter filter, int y0,
                  int y1, uint16_t* rgb);

// The display image of `display`'s size from a flat image of view.width × view.height pixels:
// resampleRows over every row of resampleWarp(view, display), with its counts.
ResampledImage resampleFlatImage(const FlatView& view, const uint16_t* flatRgb,
                                 const DirectionMap& display, ResampleFilter filter);

// The smallest angle between the directions of two valid display pixels that are neighbours in a
// row or a column, radians: the display's finest angular pixel. 0 when no two valid pixels
// neighbour.
double finestAngularPixel(const DirectionMap& display);

// The orientation looking along the mean of the display's valid directions, level (no roll; the
// pitch from the mean's elevation). The straight-ahead orientation when there is none.
Orientation meanOrientation(const DirectionMap& display);

// "The flat channel with margin" for method (b): with the given orientation, the tightest window
// holding every valid direction of `display` (rounded up to whole pixels about its middle),
// widened by `marginPixels` flat pixels on each side, at the resolution whose tangent step is the
// display's finest angular pixel — every flat pixel then subtends at most that angle (a pixel of
// tangent step δ at tangent (t, s) subtends δ·√(1 + s²)/(1 + t² + s²) ≤ δ). Fails when a valid
// direction points behind or beside the orientation (no flat window holds it), when the display
// has no valid pixel or no two valid neighbours, or when a side would exceed `maxSide` pixels.
Result<FlatView> coveringFlatView(const DirectionMap& display, const Orientation& orientation,
                                  int marginPixels = 2, int maxSide = 8192);

}  // namespace sv::display
