// Based on: SPEC §11 (height tables); issue 29 (terrain from DEM files: GDAL rasters). GDAL's raster data model (geotransform, no-data, scale and
// offset): https://gdal.org/user/raster_data_model.html.
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
#include "formats/heights.h"
#include "synthvis/files.h"

namespace sv::formats {
using namespace gdal;
using detail::checkPlacement;
using detail::finite;

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
  std::string file = core::fileName(name);
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

}  // namespace sv::formats
