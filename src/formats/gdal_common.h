// GDAL for the terrain loaders (heights.cpp, ortho_image.cpp): driver registration, errors
// as one line, and a raster's georeferencing as map placement.
#pragma once

#include <cpl_error.h>
#include <fmt/format.h>
#include <gdal.h>

#include <algorithm>
#include <mutex>
#include <string>

#include "formats/heights.h"
#include "synthvis/result.h"

namespace sv::formats::gdal {

// GDAL's drivers are registered once per process, whoever loads first (GDALAllRegister is not
// safe to run concurrently with itself).
inline void registerGdal() {
  static std::once_flag once;
  std::call_once(once, [] { GDALAllRegister(); });
}

// While alive, GDAL's errors on this thread are recorded (CPLGetLastErrorMsg) but not printed:
// they reach the caller as our one-line Error instead. GDAL's handler stack is per thread.
class QuietGdalErrors {
 public:
  QuietGdalErrors() {
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLErrorReset();
  }
  ~QuietGdalErrors() { CPLPopErrorHandler(); }
  QuietGdalErrors(const QuietGdalErrors&) = delete;
  QuietGdalErrors& operator=(const QuietGdalErrors&) = delete;
};

// GDAL's last error as one line, `what` when it recorded none; the /vsimem/ path of an in-memory
// load replaced by the name the caller knows.
inline std::string gdalMessage(const char* what, const std::string& gdalPath,
                               const std::string& name) {
  std::string m = CPLGetLastErrorMsg();
  if (m.empty()) return what;
  // GDAL often opens with the path ("x.tif: No such file", "x.tif, band 1: …"), which our Error
  // names already.
  for (const char* separator : {": ", ", "})
    if (m.rfind(gdalPath + separator, 0) == 0) m.erase(0, gdalPath.size() + 2);
  for (size_t at = 0; (at = m.find(gdalPath, at)) != std::string::npos; at += name.size())
    m.replace(at, gdalPath.size(), name);
  std::replace_if(
      m.begin(), m.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
  while (!m.empty() && (m.back() == ' ' || m.back() == '.')) m.pop_back();
  return fmt::format("{}: {}", what, m);
}

struct DatasetCloser {
  void operator()(void* ds) const { GDALClose(ds); }
};

// Where a raster's pixel centres lie on the map (height_field.h's conventions): the centre of
// pixel (0, 0) and the spacing east and south, from the geotransform (north-up only; a geographic
// raster's degrees converted to metres at its centre latitude); spacing 1 and origin 0 without
// one (georeferenced false). `source` names the raster in errors.
struct GridPlacement {
  double originU = 0, originV = 0, spacingU = 1, spacingV = 1;
  bool georeferenced = false;
  HeightField::Geographic geographic;  // a geographic raster's own grid (height_field.h)
};
Result<GridPlacement> gridPlacement(GDALDatasetH ds, int width, int height,
                                    const std::string& source);

}  // namespace sv::formats::gdal
