// Based on: SPEC §11 (height tables); issue 29 (terrain from DEM files: GDAL rasters, 16-bit PNG
// height maps, mosaics of tiles). GDAL's raster data model (geotransform, no-data, scale and
// offset): https://gdal.org/user/raster_data_model.html.
#include "formats/heights.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_vsi.h>
#include <fmt/format.h>
#include <gdal.h>
#include <ogr_srs_api.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>

#include "formats/gdal_common.h"
#include "texture/png.h"

namespace sv::formats {
using namespace gdal;

GeoFrame ownFrame(const HeightField::Geographic& g, int width, int height) {
  const double degrees = g.radiansPerUnit * 180 / M_PI;
  return GeoFrame(GeoPoint{(g.lat0 - 0.5 * (height - 1) * g.dLat) * degrees,
                           (g.lon0 + 0.5 * (width - 1) * g.dLon) * degrees, 0});
}

void placeGeographic(const HeightField::Geographic& g, const GeoFrame& frame, HeightField& f) {
  const double degrees = g.radiansPerUnit * 180 / M_PI;
  f.originU = frame.east(g.lon0 * degrees);
  f.originV = frame.north(g.lat0 * degrees);
  f.spacingU = g.dLon * degrees * frame.metresPerDegreeEast();
  f.spacingV = g.dLat * degrees * frame.metresPerDegreeNorth();
}

namespace {

// Map positions and extents beyond this are not a ground (the Earth's circumference is 4·10⁷ m):
// they come from a broken file, and would lose the precision of the positions they are added to.
constexpr double kMaxExtent = 1e8;  // metres

bool finite(std::initializer_list<double> values) {
  return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
}

// The origin and spacing `f` has, against kMaxExtent; `source` names it.
std::optional<Error> checkPlacement(const HeightField& f, const std::string& source) {
  if (!finite({f.originU, f.originV, f.spacingU, f.spacingV}) || !(f.spacingU > 0) ||
      !(f.spacingV > 0))
    return Error{source, "",
                 fmt::format("sample spacing {} × {} m at origin ({}, {}) is not a positive, "
                             "finite placement",
                             f.spacingU, f.spacingV, f.originU, f.originV)};
  const double extent = std::max(
      {std::fabs(f.originU), std::fabs(f.eastU()), std::fabs(f.originV), std::fabs(f.southV())});
  if (!(extent < kMaxExtent))
    return Error{source, "",
                 fmt::format("map extent u {} … {}, v {} … {} m reaches beyond ±{:g} m", f.originU,
                             f.eastU(), f.southV(), f.originV, kMaxExtent)};
  return std::nullopt;
}

}  // namespace

namespace gdal {

Result<GridPlacement> gridPlacement(GDALDatasetH ds, int width, int height,
                                    const std::string& source) {
  // Step 2: the geotransform: x = gt0 + col·gt1 + row·gt2, y = gt3 + col·gt4 + row·gt5 at the
  // corner (col, row) of a pixel — so the centre of pixel (0, 0) is half a pixel in.
  // Without one GDAL states (0, 1, 0, 0, 0, 1), a south-up grid: ours is spacing 1 and origin 0.
  double gt[6];
  const bool georeferenced = GDALGetGeoTransform(ds, gt) == CE_None;
  CPLErrorReset();  // no geotransform is not an error
  if (georeferenced) {
    if (!finite({gt[0], gt[1], gt[2], gt[3], gt[4], gt[5]}))
      return Error{source, "", "the raster's geotransform is not finite"};
    if (gt[2] != 0 || gt[4] != 0)
      return Error{source, "",
                   fmt::format("rotated or sheared raster (geotransform terms {} and {}): only "
                               "north-up rasters are supported",
                               gt[2], gt[4])};
    if (!(gt[1] > 0) || !(gt[5] < 0))
      return Error{source, "",
                   fmt::format("pixel size {} × {}: only north-up rasters (columns east, rows "
                               "south) are supported",
                               gt[1], gt[5])};
  }
  HeightField placed;
  placed.width = width;
  placed.height = height;
  if (georeferenced) {
    placed.originU = gt[0] + 0.5 * gt[1];
    placed.originV = gt[3] + 0.5 * gt[5];
    placed.spacingU = gt[1];
    placed.spacingV = -gt[5];
  }
  // A geographic raster: degrees (or the SRS's angular unit) to map metres of the WGS 84 frame at
  // its own centre (synthvis/geodesy.h; a scene's geodetic frame re-places it: placeGeographic).
  // The geotransform is in longitude, latitude order whatever the SRS's axis order (GDAL's
  // "traditional GIS order" for rasters).
  HeightField::Geographic geographic;
  if (georeferenced) {
    if (OGRSpatialReferenceH srs = GDALGetSpatialRef(ds); srs && OSRIsGeographic(srs)) {
      const double radiansPerUnit = OSRGetAngularUnits(srs, nullptr);
      const double lat0 = gt[3] + 0.5 * height * gt[5];
      const double lat0Radians = lat0 * radiansPerUnit;
      if (!(radiansPerUnit > 0) || !(std::fabs(lat0Radians) < 0.5 * M_PI))
        return Error{source, "",
                     fmt::format("geographic raster centred at latitude {} (unit {} rad) is not "
                                 "on the sphere",
                                 lat0, radiansPerUnit)};
      geographic = {true,          placed.originU, placed.originV, placed.spacingU, placed.spacingV,
                    radiansPerUnit};
      placeGeographic(geographic, ownFrame(geographic, width, height), placed);
    }
  }
  if (std::optional<Error> e = checkPlacement(placed, source)) return *e;
  return GridPlacement{placed.originU,  placed.originV, placed.spacingU,
                       placed.spacingV, georeferenced,  geographic};
}

}  // namespace gdal

namespace {

// Band 1 of the open dataset `ds` as a height table. `gdalPath` is what GDAL was given, `source`
// what the caller calls it; at most `maxSamples` samples.
Result<HeightField> readDataset(GDALDatasetH ds, const std::string& gdalPath,
                                const std::string& source, int64_t maxSamples) {
  // Step 1: the size, refused before anything is allocated.
  const int width = GDALGetRasterXSize(ds), height = GDALGetRasterYSize(ds);
  if (GDALGetRasterCount(ds) < 1) return Error{source, "", "the raster has no band"};
  if (width < 2 || height < 2)
    return Error{
        source, "",
        fmt::format("a height table needs at least 2 × 2 samples, not {} × {}", width, height)};
  const int64_t samples = int64_t(width) * height;
  if (width > kMaxHeightSide || height > kMaxHeightSide ||
      samples > std::min(kMaxHeightSamples, maxSamples))
    return Error{source, "",
                 fmt::format("{} × {} heights exceed the limit of {} a side and {} in all", width,
                             height, kMaxHeightSide, std::min(kMaxHeightSamples, maxSamples))};
  GDALRasterBandH band = GDALGetRasterBand(ds, 1);
  if (!band) return Error{source, "", gdalMessage("cannot read band 1", gdalPath, source)};

  // Step 2: where the samples lie (gdal_common.h).
  Result<GridPlacement> grid = gridPlacement(ds, width, height, source);
  if (!grid) return grid.error();
  HeightField placed;
  placed.originU = grid->originU, placed.originV = grid->originV;
  placed.spacingU = grid->spacingU, placed.spacingV = grid->spacingV;

  // Step 3: the samples, in chunks of rows as doubles (GDAL converts any type), no-data to NaN,
  // then the band's scale and offset (value = offset + scale·raw, GDAL's convention).
  int hasNoData = 0, hasScale = 0, hasOffset = 0;
  const double noData = GDALGetRasterNoDataValue(band, &hasNoData);
  double scale = GDALGetRasterScale(band, &hasScale),
         offset = GDALGetRasterOffset(band, &hasOffset);
  if (!hasScale) scale = 1;
  if (!hasOffset) offset = 0;
  if (!finite({scale, offset}) || scale == 0)
    return Error{source, "",
                 fmt::format("band 1's scale {} and offset {} do not give heights", scale, offset)};
  // A float32 band's no-data value is matched in float32, as GDAL does: the value its metadata
  // states in decimal may round differently from the stored samples in double.
  const bool float32 = GDALGetRasterDataType(band) == GDT_Float32;
  auto isNoData = [&](double raw) {
    if (!hasNoData) return false;
    return float32 ? float(raw) == float(noData) : raw == noData;
  };
  std::vector<double> values(static_cast<size_t>(samples));
  const int rowsPerChunk = std::max(1, (1 << 20) / width);
  for (int row = 0; row < height; row += rowsPerChunk) {
    const int rows = std::min(rowsPerChunk, height - row);
    double* chunk = values.data() + size_t(row) * size_t(width);
    if (GDALRasterIO(band, GF_Read, 0, row, width, rows, chunk, width, rows, GDT_Float64, 0, 0) !=
        CE_None)
      return Error{source, fmt::format("row {}", row),
                   gdalMessage("cannot read the raster's samples", gdalPath, source)};
    for (size_t k = 0; k < size_t(rows) * size_t(width); ++k)
      chunk[k] =
          isNoData(chunk[k]) ? std::numeric_limits<double>::quiet_NaN() : offset + scale * chunk[k];
  }

  // Step 4: to 16 bits, placed.
  Result<HeightField> f = quantize(values, width, height, source);
  if (!f.ok()) return f;
  f->originU = placed.originU;
  f->originV = placed.originV;
  f->spacingU = placed.spacingU;
  f->spacingV = placed.spacingV;
  f->geographic = grid->geographic;
  return f;
}

// Opens `gdalPath` read-only with `drivers` (null: all) and reads it.
Result<HeightField> openAndRead(const std::string& gdalPath, const std::string& source,
                                const char* const* drivers, int64_t maxSamples) {
  registerGdal();
  QuietGdalErrors quiet;
  std::unique_ptr<void, DatasetCloser> ds(
      GDALOpenEx(gdalPath.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY | GDAL_OF_VERBOSE_ERROR,
                 drivers, nullptr, nullptr));
  if (!ds) return Error{source, "", gdalMessage("cannot open raster", gdalPath, source)};
  return readDataset(ds.get(), gdalPath, source, maxSamples);
}

// The caller's height scale and offset, checked before the file is read: an error in them is the
// caller's, whatever the file holds.
std::optional<Error> checkHeightScale(const PngPlacement& placement, const std::string& name) {
  if (!finite({placement.offset, placement.scale}) || !(placement.scale > 0))
    return Error{name, "",
                 fmt::format("PNG height scale {} and offset {} are not a positive scale and a "
                             "finite offset",
                             placement.scale, placement.offset)};
  return std::nullopt;
}

texture::PngLimits pngLimits(int64_t maxSamples) {
  texture::PngLimits limits;
  limits.maxSide = kMaxHeightSide;
  limits.maxPixels = std::min(kMaxHeightSamples, maxSamples);
  return limits;
}

// A decoded grey PNG as a height table: its codes unchanged, offset + scale·code metres, placed
// where the caller says.
Result<HeightField> placePng(Result<texture::PngGrey> png, const std::string& name,
                             const PngPlacement& placement) {
  if (!png.ok()) return png.error();
  if (png->width < 2 || png->height < 2)
    return Error{name, "",
                 fmt::format("a height table needs at least 2 × 2 samples, not {} × {}", png->width,
                             png->height)};
  HeightField f;
  f.width = png->width;
  f.height = png->height;
  f.originU = placement.originU;
  f.originV = placement.originV;
  f.spacingU = placement.spacingU;
  f.spacingV = placement.spacingV;
  if (std::optional<Error> e = checkPlacement(f, name)) return *e;
  // The same bound as quantize's, on the heights the codes can stand for.
  const double top = placement.offset + placement.scale * ((1 << png->bitDepth) - 1);
  if (std::fabs(placement.offset) > 1e7 || std::fabs(top) > 1e7)
    return Error{name, "",
                 fmt::format("heights from {} to {} are beyond ±10 000 km", placement.offset, top)};
  f.offset = placement.offset;
  f.scale = placement.scale;
  f.q = std::move(png->samples);
  f.source = name;
  return f;
}

bool endsWithPng(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".png";
}

}  // namespace

Result<HeightField> loadGdal(const std::string& path) {
  return openAndRead(path, path, nullptr, kMaxHeightSamples);
}

Result<HeightField> loadGdalFromMemory(const std::string& bytes, const std::string& name,
                                       int64_t maxSamples) {
  // Drivers that read one file and nothing it names (height_field.h): untrusted bytes must not
  // reach other files (VRT sources, GDAL's raw bands) or the network (WMS and other services).
  static constexpr const char* kDrivers[] = {"GTiff", "SRTMHGT", "AAIGrid", "USGSDEM", "GSAG",
                                             "GSBG",  "GS7BG",   "BT",      nullptr};
  // A directory of its own per call (loads may run concurrently), holding the file under the
  // caller's file name: the SRTMHGT driver reads the tile's position from it.
  static std::atomic<uint64_t> calls{0};
  std::string file = name.substr(name.find_last_of('/') + 1);
  if (file.empty()) file = "heights";
  const std::string dir = fmt::format("/vsimem/synthvis-heights-{}", calls++);
  const std::string gdalPath = dir + "/" + file;
  registerGdal();
  // GDAL only reads the buffer (opened read-only, unlinked before returning), so the const_cast
  // is safe and saves a copy; bOwnData = FALSE leaves it ours.
  VSILFILE* handle = VSIFileFromMemBuffer(gdalPath.c_str(),
                                          reinterpret_cast<GByte*>(const_cast<char*>(bytes.data())),
                                          vsi_l_offset(bytes.size()), FALSE);
  if (!handle) return Error{name, "", "cannot place the bytes in GDAL's memory file system"};
  VSIFCloseL(handle);
  Result<HeightField> f = openAndRead(gdalPath, name, kDrivers, maxSamples);
  VSIRmdirRecursive(dir.c_str());  // the file and anything a driver put beside it
  return f;
}

Result<HeightField> decodePng16(const void* data, size_t size, const std::string& name,
                                const PngPlacement& placement, int64_t maxSamples) {
  if (std::optional<Error> e = checkHeightScale(placement, name)) return *e;
  return placePng(texture::decodePngGrey(data, size, name, pngLimits(maxSamples)), name, placement);
}

Result<HeightField> loadPng16(const std::string& path, const PngPlacement& placement) {
  if (std::optional<Error> e = checkHeightScale(placement, path)) return *e;
  return placePng(texture::readPngGrey(path, pngLimits(kMaxHeightSamples)), path, placement);
}

Result<HeightField> loadHeights(const std::string& path, const PngPlacement& pngPlacement) {
  return endsWithPng(path) ? loadPng16(path, pngPlacement) : loadGdal(path);
}

namespace {

// Geographic tiles converted to metres at one latitude, the union's centre (each loaded alone was
// converted at its own, which gives tiles in different rows different east–west spacings).
Result<std::vector<HeightField>> onOneLatitude(const std::vector<HeightField>& tiles) {
  double top = -1e300, bottom = 1e300;
  for (const HeightField& t : tiles) {
    if (t.geographic.on != tiles.front().geographic.on)
      return Error{t.source, "",
                   fmt::format("is {} but {} is not: a mosaic's tiles share one kind of grid",
                               t.geographic.on ? "geographic" : "projected", tiles.front().source)};
    top = std::max(top, t.geographic.lat0 * t.geographic.radiansPerUnit);
    bottom = std::min(bottom, (t.geographic.lat0 - (t.height - 1) * t.geographic.dLat) *
                                  t.geographic.radiansPerUnit);
  }
  const HeightField::Geographic& g = tiles.front().geographic;
  const double degrees = 180 / M_PI;
  const GeoFrame frame(
      GeoPoint{0.5 * (top + bottom) * degrees, g.lon0 * g.radiansPerUnit * degrees, 0});
  std::vector<HeightField> out = tiles;
  for (HeightField& t : out) placeGeographic(t.geographic, frame, t);
  return out;
}

}  // namespace

Result<HeightField> mosaic(const std::vector<HeightField>& given) {
  if (given.empty()) return Error{"", "", "a mosaic needs at least one tile"};
  std::vector<HeightField> replaced;
  if (std::any_of(given.begin(), given.end(),
                  [](const HeightField& t) { return t.geographic.on; })) {
    Result<std::vector<HeightField>> r = onOneLatitude(given);
    if (!r) return r.error();
    replaced = std::move(r.value());
  }
  const std::vector<HeightField>& tiles = replaced.empty() ? given : replaced;
  for (const HeightField& t : tiles) {
    if (t.width < 1 || t.height < 1 || t.q.size() != size_t(t.width) * size_t(t.height))
      return Error{t.source, "", "the tile's table does not match its size"};
    if (std::optional<Error> e = checkPlacement(t, t.source)) return *e;
  }
  // Step 1: one grid, the first tile's: each tile's spacing the same (to 1e-9 relative), its
  // origin on the grid (to 1/1000 of a step); (ci, cj) is its sample (0, 0) in grid steps from
  // the first tile's, columns east and rows south.
  const HeightField& first = tiles.front();
  const double su = first.spacingU, sv = first.spacingV;
  std::vector<int64_t> ci(tiles.size()), cj(tiles.size());
  int64_t minI = 0, minJ = 0, maxI = 0, maxJ = 0;
  for (size_t t = 0; t < tiles.size(); ++t) {
    const HeightField& tile = tiles[t];
    if (std::fabs(tile.spacingU - su) > 1e-9 * su || std::fabs(tile.spacingV - sv) > 1e-9 * sv)
      return Error{tile.source, "",
                   fmt::format("spacing {} × {} m differs from {}'s {} × {} m: mosaic tiles must "
                               "share one grid",
                               tile.spacingU, tile.spacingV, first.source, su, sv)};
    // Bounded by checkPlacement's extents, but not the spacing: a step count beyond the largest
    // mosaic cannot be placed in one anyway.
    const double fi = (tile.originU - first.originU) / su, fj = (first.originV - tile.originV) / sv;
    if (!(std::fabs(fi) < 1e9 && std::fabs(fj) < 1e9) || std::fabs(fi - std::round(fi)) > 1e-3 ||
        std::fabs(fj - std::round(fj)) > 1e-3)
      return Error{tile.source, "",
                   fmt::format("origin ({}, {}) is {} × {} steps from {}'s, not on its grid",
                               tile.originU, tile.originV, fi, fj, first.source)};
    ci[t] = int64_t(std::llround(fi));
    cj[t] = int64_t(std::llround(fj));
    minI = std::min(minI, ci[t]);
    minJ = std::min(minJ, cj[t]);
    maxI = std::max(maxI, ci[t] + tile.width - 1);
    maxJ = std::max(maxJ, cj[t] + tile.height - 1);
  }
  const int64_t width = maxI - minI + 1, height = maxJ - minJ + 1;
  const std::string source = fmt::format("mosaic of {} tiles from {}", tiles.size(), first.source);
  if (width > kMaxHeightSide || height > kMaxHeightSide || width * height > kMaxHeightSamples)
    return Error{source, "",
                 fmt::format("the tiles span {} × {} samples, beyond the limit of {} a side", width,
                             height, kMaxHeightSide)};

  // Step 2: every tile's heights into the union (NaN where none lands), each shared sample
  // checked against the tile that wrote it first. Each tile's heights are within half its step
  // of the truth, so two tiles holding the same sample differ by at most the sum of their half
  // steps ≤ the coarser step; 1e-9 of the height is for the rounding of offset + scale·q.
  std::vector<double> values(size_t(width) * size_t(height),
                             std::numeric_limits<double>::quiet_NaN());
  std::vector<int32_t> writer(values.size(), -1);
  for (size_t t = 0; t < tiles.size(); ++t) {
    const HeightField& tile = tiles[t];
    for (int j = 0; j < tile.height; ++j) {
      const size_t row = size_t(cj[t] - minJ + j) * size_t(width) + size_t(ci[t] - minI);
      for (int i = 0; i < tile.width; ++i) {
        const double h = tile.at(i, j);
        const size_t k = row + size_t(i);
        if (writer[k] < 0) {
          values[k] = h;
          writer[k] = int32_t(t);
          continue;
        }
        const HeightField& other = tiles[size_t(writer[k])];
        const double tolerance = std::max(tile.scale, other.scale) + 1e-9 * std::fabs(h);
        if (std::fabs(h - values[k]) > tolerance)
          return Error{tile.source, "",
                       fmt::format("height {} m at map ({}, {}) disagrees with {}'s {} m where "
                                   "the tiles overlap",
                                   h, tile.originU + i * su, tile.originV - j * sv, other.source,
                                   values[k])};
      }
    }
  }

  // Step 3: requantized over the union's range, placed at the union's north-west sample.
  Result<HeightField> f = quantize(values, int(width), int(height), source);
  if (!f.ok()) return f;
  f->originU = first.originU + double(minI) * su;
  f->originV = first.originV - double(minJ) * sv;
  f->spacingU = su;
  f->spacingV = sv;
  if (first.geographic.on) {
    f->geographic = first.geographic;
    f->geographic.lon0 += double(minI) * first.geographic.dLon;
    f->geographic.lat0 -= double(minJ) * first.geographic.dLat;
  }
  return f;
}

}  // namespace sv::formats
