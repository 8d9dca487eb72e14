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

}  // namespace sv::terrain
