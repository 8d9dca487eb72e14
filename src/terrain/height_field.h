// Height fields (SPEC §11, seed 003's scalar perturbations): a 2D table of heights over a base
// surface, displaced along the base's normal, defined in the infinite prism over the table's
// footprint — the ground of a flight or driving simulator.
//
// Map coordinates. A table is a grid of `width` × `height` samples, row 0 the northern edge (the
// order GDAL and image files keep). Sample (i, j) sits at map position
//   u = originU + i·spacingU  (east),   v = originV − j·spacingV  (north),
// in metres. Heights are metres up along the base's normal, held at 16 bits:
//   h = offset + scale·q,  q ∈ [0, 65535]  (SPEC §11 does not fix a precision; 16 bits with the
// table's own scale keep 1/65535 of its range — 0.15 m over a 10 km range — at a quarter of the
// memory of double, and a 16384² table fits in 512 MB).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "synthvis/result.h"

namespace sv::terrain {

// The largest table accepted, a side and in all (issue 29: maps up to 16384² in memory). Loaders
// refuse anything larger — or a header declaring it — before allocating.
inline constexpr int kMaxSide = 16384;
inline constexpr int64_t kMaxSamples = int64_t(kMaxSide) * kMaxSide;

// How heights between the samples are interpolated (SPEC §11): bilinearly, or bicubically by the
// Catmull–Rom spline, which passes through the samples (and so may overshoot them: the pyramid's
// bounds include the overshoot, pyramid.h).
enum class Interpolation : uint8_t { bilinear, bicubic };
Result<Interpolation> parseInterpolation(const std::string& name);  // "bilinear" | "bicubic"
const char* interpolationName(Interpolation i);

struct HeightField {
  int width = 0, height = 0;  // samples
  double originU = 0, originV = 0;      // map position of sample (0, 0), metres
  double spacingU = 1, spacingV = 1;    // metres between samples, east and south (> 0)
  double offset = 0, scale = 1;         // h = offset + scale·q
  std::vector<uint16_t> q;              // width × height, row-major, row 0 north
  std::string source;                   // the file (or generator) it came from, for messages
  // A geographic raster's own grid (loadGdal): sample (0, 0) at (lon0, lat0), steps dLon east
  // and dLat south, in the SRS's angular unit (radiansPerUnit); the placement above is its
  // conversion to metres at the table's centre latitude. A mosaic of such tiles converts them all
  // at the union's centre latitude, so tiles in different rows share one grid.
  struct Geographic {
    bool on = false;
    double lon0 = 0, lat0 = 0, dLon = 0, dLat = 0, radiansPerUnit = 0;
  } geographic;

  double at(int i, int j) const {
    return offset + scale * q[size_t(j) * size_t(width) + size_t(i)];
  }
  uint16_t code(int i, int j) const { return q[size_t(j) * size_t(width) + size_t(i)]; }
  // Map extent: u from originU to eastU(), v from southV() to originV.
  double eastU() const { return originU + (width - 1) * spacingU; }
  double southV() const { return originV - (height - 1) * spacingV; }
  size_t bytes() const { return q.size() * sizeof(uint16_t); }
};

// Heights given in any unit as doubles (NaN: no data), to a HeightField: scale and offset chosen
// so that the smallest and largest valid heights map to codes 0 and 65535; no-data samples take
// the smallest valid height (documented in docs/terrain.md; a table without one valid sample is
// an error). `values` is row-major, width × height.
Result<HeightField> quantize(const std::vector<double>& values, int width, int height,
                             const std::string& source);

// The interpolated height at grid position (x, y) (x = (u − originU)/spacingU, y = (originV −
// v)/spacingV; samples at integers), and its derivatives ∂h/∂x, ∂h/∂y per grid step, positions
// clamped to the table. Bicubic reads the 4×4 samples around the cell, edge samples repeated
// beyond the border. Both reproduce the table exactly at grid points.
double interpolate(const HeightField& f, Interpolation interp, double x, double y,
                   double* dx = nullptr, double* dy = nullptr);

// A seeded fractal table (midpoint displacement, the displacement × 0.6 per halving — fractal
// dimension ≈ 2.3, as mountains measure — plus a ridge and valley overlay), `size` × `size` samples
// `spacing` metres apart, heights spanning [0, relief] metres, centred on map origin (0, 0). The
// same seed gives the same table on every machine.
Result<HeightField> generateFractal(int size, double spacing, double relief, uint32_t seed);

// Loaders (load_heights.cpp), each with one-line errors naming the file and the problem, and
// each refusing a size beyond kMaxSide / kMaxSamples (or the `maxSamples` budget of the in-memory
// forms) before reading a sample:
// - loadGdal: any raster GDAL reads (GeoTIFF, SRTM .hgt, …), band 1 (samples equal to its no-data
//   value are no data, quantize's rule; its scale and offset applied), placed by its geotransform
//   with (originU, originV) the centre of pixel (0, 0). Only north-up rasters (no rotation or
//   shear, rows running south). A projected raster's units are taken as metres; a geographic
//   one's degrees become metres by the equirectangular projection with standard parallel at the
//   raster's centre latitude lat0 on a sphere of radius kEarthRadius: u = R·cos(lat0)·λ,
//   v = R·φ (λ, φ longitude and latitude in radians), so the raster's centre (λ0, φ0) lands at
//   (R·cos(lat0)·λ0, R·φ0) — true to scale along lat0 and along meridians, east–west scale off by
//   cos(φ)/cos(lat0) away from it (1.7 % at 1° from lat0 = 45°). A raster without a geotransform
//   gets spacing 1 and origin (0, 0).
// - loadGdalFromMemory: the same from `bytes` (through GDAL's /vsimem/), `name` naming them in
//   errors and giving drivers that read it (SRTM .hgt) the file name. For untrusted input: only
//   drivers that read one self-contained file (GTiff, SRTMHGT, AAIGrid, USGSDEM, the Surfer grids,
//   BT) — no VRT or service descriptions, which would open other files or the network.
// - loadPng16: a 16-bit greyscale PNG (8-bit accepted), codes as heights offset + scale·code with
//   the caller's spacing and origin (a PNG holds no georeferencing): the table holds the file's
//   codes unchanged. decodePng16 reads PNG bytes in memory.
inline constexpr double kEarthRadius = 6371008.8;  // metres, the mean radius (IUGG)
Result<HeightField> loadGdal(const std::string& path);
Result<HeightField> loadGdalFromMemory(const std::string& bytes, const std::string& name,
                                       int64_t maxSamples = kMaxSamples);
struct PngPlacement {
  double originU = 0, originV = 0, spacingU = 1, spacingV = 1, offset = 0, scale = 1;
};
Result<HeightField> loadPng16(const std::string& path, const PngPlacement& placement);
Result<HeightField> decodePng16(const void* data, size_t size, const std::string& name,
                                const PngPlacement& placement, int64_t maxSamples = kMaxSamples);
// By extension: .png (any case) → loadPng16, anything else → loadGdal.
Result<HeightField> loadHeights(const std::string& path, const PngPlacement& pngPlacement);

// Several tables side by side as one ground (a DEM mosaic): placed by their map positions on one
// grid — all the same spacing, aligned to it (to 1/1000 of a step), samples shared where tiles
// overlap (SRTM tiles repeat their edge rows) required to agree to the coarser of their
// quantizations — and merged into one table, so the ground has no seams to crack at. Samples no
// tile covers take the lowest height. The result is requantized over the union's range.
Result<HeightField> mosaic(const std::vector<HeightField>& tiles);

}  // namespace sv::terrain
