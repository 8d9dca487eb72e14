// Based on: SPEC §7 (seed 001's texture defined by a plane — here the map plane the image is
// georeferenced on); GDAL's raster data model for the bands and geotransform.
#include "formats/ortho_image.h"

#include <cpl_error.h>
#include <fmt/format.h>
#include <gdal.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "formats/gdal_common.h"

namespace sv::formats {
namespace {

// The outer edges of a grid of pixel centres: half a pixel beyond the outermost centres.
std::array<double, 4> outerEdges(double originU, double originV, double spacingU, double spacingV,
                                 int width, int height) {
  return {originU - 0.5 * spacingU, originV - (height - 0.5) * spacingV,
          originU + (width - 0.5) * spacingU, originV + 0.5 * spacingV};
}

// sRGB-encoded [0, 1] to linear light (IEC 61966-2-1).
double srgbToLinear(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

}  // namespace

Result<OrthoImage> loadOrthoImage(const std::string& path, const std::array<int, 3>& bands) {
  gdal::registerGdal();
  gdal::QuietGdalErrors quiet;
  std::unique_ptr<void, gdal::DatasetCloser> ds(
      GDALOpenEx(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY, nullptr, nullptr, nullptr));
  if (!ds) return Error{path, "", gdal::gdalMessage("cannot open image", path, path)};
  const int width = GDALGetRasterXSize(ds.get()), height = GDALGetRasterYSize(ds.get());
  const int count = GDALGetRasterCount(ds.get());
  if (width < 1 || height < 1 || width > texture::kMaxTextureSide ||
      height > texture::kMaxTextureSide || int64_t(width) * height > texture::kMaxTextureTexels)
    return Error{path, "",
                 fmt::format("{} × {} pixels exceed the texture limit of {} a side and {} in all",
                             width, height, texture::kMaxTextureSide, texture::kMaxTextureTexels)};
  for (int b : bands)
    if (b < 1 || b > count)
      return Error{path, "", fmt::format("band {} asked for; the image has {}", b, count)};
  Result<gdal::GridPlacement> grid = gdal::gridPlacement(ds.get(), width, height, path);
  if (!grid) return grid.error();
  OrthoImage out;
  out.georeferenced = grid->georeferenced;
  out.geographic = grid->geographic;
  out.bounds =
      outerEdges(grid->originU, grid->originV, grid->spacingU, grid->spacingV, width, height);
  out.level.width = width;
  out.level.height = height;
  out.level.texels.resize(size_t(width) * size_t(height));
  const size_t n = size_t(width) * size_t(height);
  std::vector<double> values(n);
  for (int c = 0; c < 3; ++c) {
    GDALRasterBandH band = GDALGetRasterBand(ds.get(), bands[size_t(c)]);
    if (!band || GDALRasterIO(band, GF_Read, 0, 0, width, height, values.data(), width, height,
                              GDT_Float64, 0, 0) != CE_None)
      return Error{path, "", gdal::gdalMessage("cannot read the image's band", path, path)};
    int hasNoData = 0;
    const double noData = GDALGetRasterNoDataValue(band, &hasNoData);
    // The 2nd and 98th percentiles of the valid values: the stretch.
    std::vector<double> valid;
    valid.reserve(n);
    for (double v : values)
      if (std::isfinite(v) && !(hasNoData && v == noData)) valid.push_back(v);
    double lo = 0, hi = 1;
    if (!valid.empty()) {
      const size_t a = valid.size() * 2 / 100,
                   b = std::min(valid.size() - 1, valid.size() * 98 / 100);
      std::nth_element(valid.begin(), valid.begin() + long(a), valid.end());
      lo = valid[a];
      std::nth_element(valid.begin(), valid.begin() + long(b), valid.end());
      hi = valid[b];
    }
    const double span = hi > lo ? hi - lo : 1;
    for (size_t k = 0; k < n; ++k) {
      const double v = std::isfinite(values[k]) ? std::clamp((values[k] - lo) / span, 0.0, 1.0) : 0;
      const uint16_t code = uint16_t(std::lround(srgbToLinear(v) * 65535));
      texture::Texel& t = out.level.texels[k];
      (c == 0 ? t.r : c == 1 ? t.g : t.b) = code;
      t.a = 65535;
    }
  }
  return out;
}

void placeGeographic(OrthoImage& image, const GeoFrame& frame) {
  if (!image.geographic.on) return;
  HeightField placed;
  placeGeographic(image.geographic, frame, placed);
  image.bounds = outerEdges(placed.originU, placed.originV, placed.spacingU, placed.spacingV,
                            image.level.width, image.level.height);
}

}  // namespace sv::formats
