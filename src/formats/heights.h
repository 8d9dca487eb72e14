// Height tables from files and from a seed (docs/terrain.md): the readers of DEM rasters and
// 16-bit PNGs, mosaics of tiles, and the fractal generator — each giving the scene's record
// (synthvis/height_field.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

#include "synthvis/geodesy.h"
#include "synthvis/height_field.h"
#include "synthvis/result.h"

namespace sv::formats {

using scene::HeightField;
using scene::kMaxHeightSamples;
using scene::kMaxHeightSide;

// Heights given in any unit as doubles (NaN: no data), to a HeightField: scale and offset chosen
// so that the smallest and largest valid heights map to codes 0 and 65535; no-data samples take
// the smallest valid height (documented in docs/terrain.md; a table without one valid sample is
// an error). `values` is row-major, width × height.
Result<HeightField> quantize(const std::vector<double>& values, int width, int height,
                             const std::string& source);

// A seeded fractal table (midpoint displacement, the displacement × 0.6 per halving — fractal
// dimension ≈ 2.3, as mountains measure — plus a ridge and valley overlay), `size` × `size` samples
// `spacing` metres apart, heights spanning [0, relief] metres, centred on map origin (0, 0). The
// same seed gives the same table on every machine.
Result<HeightField> generateFractal(int size, double spacing, double relief, uint32_t seed);

// Loaders (heights_gdal.cpp, heights_png.cpp), each with one-line errors naming the file and the problem, and
// each refusing a size beyond kMaxHeightSide / kMaxHeightSamples (or the `maxSamples` budget of the in-memory
// forms) before reading a sample:
// - loadGdal: any raster GDAL reads (GeoTIFF, SRTM .hgt, …), band 1 (samples equal to its no-data
//   value are no data, quantize's rule; its scale and offset applied), placed by its geotransform
//   with (originU, originV) the centre of pixel (0, 0). Only north-up rasters (no rotation or
//   shear, rows running south). A projected raster's units are taken as metres; a geographic
//   one's degrees become map metres of the WGS 84 frame at the raster's centre
//   (synthvis/geodesy.h: equirectangular with its standard parallel there), the grid's own
//   angles kept in `geographic` so that a scene's geodetic frame can place it again
//   (placeGeographic). A raster without a geotransform gets spacing 1 and origin (0, 0).
// - loadGdalFromMemory: the same from `bytes` (through GDAL's /vsimem/), `name` naming them in
//   errors and giving drivers that read it (SRTM .hgt) the file name. For untrusted input: only
//   drivers that read one self-contained file (GTiff, SRTMHGT, AAIGrid, USGSDEM, the Surfer grids,
//   BT) — no VRT or service descriptions, which would open other files or the network.
// - loadPng16: a 16-bit greyscale PNG (8-bit accepted), codes as heights offset + scale·code with
//   the caller's spacing and origin (a PNG holds no georeferencing): the table holds the file's
//   codes unchanged. decodePng16 reads PNG bytes in memory.
Result<HeightField> loadGdal(const std::string& path);
Result<HeightField> loadGdalFromMemory(const std::string& bytes, const std::string& name,
                                       int64_t maxSamples = kMaxHeightSamples);
struct PngPlacement {
  double originU = 0, originV = 0, spacingU = 1, spacingV = 1, offset = 0, scale = 1;
};
Result<HeightField> loadPng16(const std::string& path, const PngPlacement& placement);
Result<HeightField> decodePng16(const void* data, size_t size, const std::string& name,
                                const PngPlacement& placement,
                                int64_t maxSamples = kMaxHeightSamples);
// By extension: .png (any case) → loadPng16, anything else → loadGdal.
Result<HeightField> loadHeights(const std::string& path, const PngPlacement& pngPlacement);

// The WGS 84 frame at the centre of a geographic grid of width × height samples: where a reader
// places it when no scene frame is given.
GeoFrame ownFrame(const HeightField::Geographic& grid, int width, int height);
// Places `f` by its geographic grid in `frame`'s map metres (synthvis/geodesy.h): sample (0, 0) at
// the grid's (lon0, lat0), the spacings its steps at the frame's metres per degree — the same
// conversion the IG places its entities by.
void placeGeographic(const HeightField::Geographic& grid, const GeoFrame& frame, HeightField& f);

// Several tables side by side as one ground (a DEM mosaic): placed by their map positions on one
// grid — all the same spacing, aligned to it (to 1/1000 of a step), samples shared where tiles
// overlap (SRTM tiles repeat their edge rows) required to agree to the coarser of their
// quantizations — and merged into one table, so the ground has no seams to crack at. Samples no
// tile covers take the lowest height. The result is requantized over the union's range.
Result<HeightField> mosaic(const std::vector<HeightField>& tiles);

namespace detail {
// All of `values` finite.
bool finite(std::initializer_list<double> values);
// The problem of `f`'s origin and spacing (not finite, not positive, or a map extent beyond
// ±1e8 m: a broken file), naming `source`; nothing when it is a placement.
std::optional<Error> checkPlacement(const HeightField& f, const std::string& source);
}  // namespace detail

}  // namespace sv::formats
