// Rasters written with GDAL itself, for the tests of what reads them (the height readers, the
// terrain placed for the IG).
#pragma once

#include <gdal.h>
#include <gtest/gtest.h>
#include <ogr_srs_api.h>

#include <string>
#include <vector>

namespace sv::tests {

// Writes `values` (w × h) as a one-band raster with GDAL's `driver` at `path`: a MEM dataset
// first, then CreateCopy (SRTMHGT can only copy).
inline void writeRaster(const char* driver, const std::string& path, int w, int h,
                        GDALDataType type, const std::vector<double>& values,
                        const double* geoTransform, int epsg, const double* noData = nullptr,
                        double scale = 1, double offset = 0) {
  GDALAllRegister();
  GDALDatasetH mem = GDALCreate(GDALGetDriverByName("MEM"), "", w, h, 1, type, nullptr);
  ASSERT_NE(mem, nullptr);
  if (geoTransform) GDALSetGeoTransform(mem, const_cast<double*>(geoTransform));
  if (epsg) {
    OGRSpatialReferenceH srs = OSRNewSpatialReference(nullptr);
    ASSERT_EQ(OSRImportFromEPSG(srs, epsg), OGRERR_NONE);
    GDALSetSpatialRef(mem, srs);
    OSRDestroySpatialReference(srs);
  }
  GDALRasterBandH band = GDALGetRasterBand(mem, 1);
  if (noData) GDALSetRasterNoDataValue(band, *noData);
  if (scale != 1) GDALSetRasterScale(band, scale);
  if (offset != 0) GDALSetRasterOffset(band, offset);
  ASSERT_EQ(GDALRasterIO(band, GF_Write, 0, 0, w, h, const_cast<double*>(values.data()), w, h,
                         GDT_Float64, 0, 0),
            CE_None);
  GDALDatasetH out = GDALCreateCopy(GDALGetDriverByName(driver), path.c_str(), mem, FALSE, nullptr,
                                    nullptr, nullptr);
  ASSERT_NE(out, nullptr) << CPLGetLastErrorMsg();
  GDALClose(out);
  GDALClose(mem);
}

}  // namespace sv::tests
