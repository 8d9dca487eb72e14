// Height fields in the terrain stage (SPEC §11): how the table (synthvis/height_field.h, the
// scene's record) is interpolated between its samples.
#pragma once

#include <cstdint>
#include <string>

#include "synthvis/height_field.h"
#include "synthvis/result.h"

namespace sv::terrain {

using scene::HeightField;

// How heights between the samples are interpolated (SPEC §11): bilinearly, or bicubically by the
// Catmull–Rom spline, which passes through the samples (and so may overshoot them: the pyramid's
// bounds include the overshoot, pyramid.h).
enum class Interpolation : uint8_t { bilinear, bicubic };
Result<Interpolation> parseInterpolation(const std::string& name);  // "bilinear" | "bicubic"
const char* interpolationName(Interpolation i);

// The interpolated height at grid position (x, y) (x = (u − originU)/spacingU, y = (originV −
// v)/spacingV; samples at integers), and its derivatives ∂h/∂x, ∂h/∂y per grid step, positions
// clamped to the table. Bicubic reads the 4×4 samples around the cell, edge samples repeated
// beyond the border. Both reproduce the table exactly at grid points.
double interpolate(const HeightField& f, Interpolation interp, double x, double y,
                   double* dx = nullptr, double* dy = nullptr);

// The 4×4 codes the Catmull–Rom surface of cell (i, j) reads (edge samples repeated), h[row][col]
// from (i − 1, j − 1).
void cellSamples(const HeightField& f, int i, int j, double h[4][4]);
// The highest of the cell's patch's 16 Bézier control points (a Catmull–Rom segment p1 → p2 is the
// cubic Bézier p1, p1 + (p2 − p0)/6, p2 − (p3 − p1)/6, p2 along each axis), in codes: the surface
// over the cell stays below it — far tighter than the samples' range widened by the 9/32
// overshoot (pyramid.h).
double bezierTop(const double h[4][4]);

}  // namespace sv::terrain
