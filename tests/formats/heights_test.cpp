// The height-field loaders (load_heights.cpp) against GDAL's own C API: real DEMs from Debian's R
// example data (scripts/lib.sh, sv_terrain_data), rasters written here by GDAL, 16-bit PNGs by our
// encoder, mosaics of a generated table, and broken files.
#include "formats/heights.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <gdal.h>
#include <gtest/gtest.h>
#include <ogr_srs_api.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <numeric>
#include <string>
#include <vector>

#include "support/gdal_raster.h"
#include "texture/png.h"

namespace sv::formats {
namespace {

using sv::tests::writeRaster;

namespace fs = std::filesystem;

// WGS 84's metres per degree east (along the parallel) and north (along the meridian) at latitude
// `lat` degrees — N·cos φ and M in radians — from its defining constants, independently of
// synthvis/geodesy.h.
double wgs84MetresPerDegreeEast(double lat) {
  const double a = 6378137, f = 1 / 298.257223563, e2 = f * (2 - f), phi = lat * M_PI / 180;
  return a / std::sqrt(1 - e2 * std::sin(phi) * std::sin(phi)) * std::cos(phi) * M_PI / 180;
}
double wgs84MetresPerDegreeNorth(double lat) {
  const double a = 6378137, f = 1 / 298.257223563, e2 = f * (2 - f), phi = lat * M_PI / 180;
  const double w = std::sqrt(1 - e2 * std::sin(phi) * std::sin(phi));
  return a * (1 - e2) / (w * w * w) * M_PI / 180;
}

// A fresh directory for the running test's files (ctest runs tests in parallel processes).
fs::path tempDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir =
      fs::temp_directory_path() / (std::string("synthvis-load-test-") + info->test_suite_name() +
                                   "-" + info->name() + "-" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string readBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void writeBytes(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

// What every loader error must be: a failure, one line, naming the file.
void expectOneLineErrorNaming(const Result<HeightField>& r, const std::string& file) {
  ASSERT_FALSE(r.ok()) << file << " loaded";
  const std::string line = r.error().str();
  EXPECT_NE(line.find(file), std::string::npos) << line;
  EXPECT_EQ(line.find('\n'), std::string::npos) << line;
  EXPECT_EQ(line.find("/vsimem/"), std::string::npos) << line;
}

// GDAL opened here for the reference values, its errors kept off the test's output.
struct GdalDataset {
  explicit GdalDataset(const std::string& path) {
    GDALAllRegister();
    CPLPushErrorHandler(CPLQuietErrorHandler);
    ds = GDALOpen(path.c_str(), GA_ReadOnly);
    CPLPopErrorHandler();
  }
  ~GdalDataset() {
    if (ds) GDALClose(ds);
  }
  GdalDataset(const GdalDataset&) = delete;
  GdalDataset& operator=(const GdalDataset&) = delete;
  std::vector<double> band1() const {
    const int w = GDALGetRasterXSize(ds), h = GDALGetRasterYSize(ds);
    std::vector<double> v(size_t(w) * size_t(h));
    EXPECT_EQ(GDALRasterIO(GDALGetRasterBand(ds, 1), GF_Read, 0, 0, w, h, v.data(), w, h,
                           GDT_Float64, 0, 0),
              CE_None);
    return v;
  }
  GDALDatasetH ds = nullptr;
};

// The real DEMs: unpacked by scripts/test (sv_terrain_data) under SV_TERRAIN_DATA_DIR, which the
// environment may override. Missing data fails the test — a suite that skips what it cannot find
// proves nothing — unless SV_ALLOW_MISSING_DATA=1 says a skip is meant.
class TerrainData : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* env = std::getenv("SV_TERRAIN_DATA_DIR");
    root_ = env && *env ? env : SV_TERRAIN_DATA_DIR;
    for (const char* f : {"stars/tif/olinda_dem_utm25s.tif", "terra/ex/elev.tif"}) {
      if (fs::exists(root_ / f)) continue;
      const char* allow = std::getenv("SV_ALLOW_MISSING_DATA");
      if (allow && std::string(allow) == "1") GTEST_SKIP() << (root_ / f) << " is missing";
      FAIL() << (root_ / f)
             << " is missing: run scripts/test (or, in bash, `source scripts/lib.sh && "
                "sv_terrain_data`) to unpack the terrain test data, or set "
                "SV_ALLOW_MISSING_DATA=1 to skip";
    }
  }
  std::string path(const char* relative) const { return (root_ / relative).string(); }

 private:
  fs::path root_;
};

TEST_F(TerrainData, OlindaDemMatchesWhatGdalReports) {
  const std::string file = path("stars/tif/olinda_dem_utm25s.tif");
  const Result<HeightField> f = loadGdal(file);
  ASSERT_TRUE(f.ok()) << f.error().str();
  GdalDataset gdal(file);
  ASSERT_NE(gdal.ds, nullptr);
  double gt[6];
  ASSERT_EQ(GDALGetGeoTransform(gdal.ds, gt), CE_None);
  EXPECT_EQ(f->width, GDALGetRasterXSize(gdal.ds));
  EXPECT_EQ(f->height, GDALGetRasterYSize(gdal.ds));
  EXPECT_EQ(f->width, 111);
  EXPECT_EQ(f->height, 111);
  // UTM is metres already: the origin is the centre of pixel (0, 0), half a pixel in from the
  // geotransform's corner.
  EXPECT_DOUBLE_EQ(f->originU, gt[0] + 0.5 * gt[1]);
  EXPECT_DOUBLE_EQ(f->originV, gt[3] + 0.5 * gt[5]);
  EXPECT_DOUBLE_EQ(f->spacingU, gt[1]);
  EXPECT_DOUBLE_EQ(f->spacingV, -gt[5]);
  double minMax[2];
  ASSERT_EQ(GDALComputeRasterMinMax(GDALGetRasterBand(gdal.ds, 1), FALSE, minMax), CE_None);
  const double step = f->scale;
  EXPECT_NEAR(f->offset, minMax[0], 0.5 * step);
  EXPECT_NEAR(f->offset + 65535 * f->scale, minMax[1], 0.5 * step);
  // Every sample within half a quantization step of GDAL's.
  const std::vector<double> ref = gdal.band1();
  for (int j = 0; j < f->height; ++j)
    for (int i = 0; i < f->width; ++i)
      ASSERT_NEAR(f->at(i, j), ref[size_t(j) * 111 + size_t(i)], 0.5 * step + 1e-9)
          << "sample " << i << ", " << j;
}

TEST_F(TerrainData, GeographicElevBecomesMetresAtItsCentreLatitudeAndKeepsNoData) {
  const std::string file = path("terra/ex/elev.tif");
  const Result<HeightField> f = loadGdal(file);
  ASSERT_TRUE(f.ok()) << f.error().str();
  GdalDataset gdal(file);
  ASSERT_NE(gdal.ds, nullptr);
  double gt[6];
  ASSERT_EQ(GDALGetGeoTransform(gdal.ds, gt), CE_None);
  const int w = GDALGetRasterXSize(gdal.ds), h = GDALGetRasterYSize(gdal.ds);
  ASSERT_EQ(f->width, w);
  ASSERT_EQ(f->height, h);
  EXPECT_EQ(w, 95);
  EXPECT_EQ(h, 90);
  // The equirectangular projection on WGS 84 with its standard parallel at the raster's centre
  // (synthvis/geodesy.h), evaluated here directly: the centre (lon0, lat0) is the map's origin.
  const double lat0 = gt[3] + 0.5 * h * gt[5], lon0 = gt[0] + 0.5 * w * gt[1];
  const double kx = wgs84MetresPerDegreeEast(lat0), k = wgs84MetresPerDegreeNorth(lat0);
  EXPECT_NEAR(f->spacingU, gt[1] * kx, 1e-9 * f->spacingU);
  EXPECT_NEAR(f->spacingV, -gt[5] * k, 1e-9 * f->spacingV);
  EXPECT_NEAR(f->originU, (gt[0] + 0.5 * gt[1] - lon0) * kx, 1e-6);
  EXPECT_NEAR(f->originV, (gt[3] + 0.5 * gt[5] - lat0) * k, 1e-6);
  // The centre of the extent is the middle of the sample grid: the map's origin.
  EXPECT_NEAR(0.5 * (f->originU + f->eastU()), 0, 1e-6);
  EXPECT_NEAR(0.5 * (f->originV + f->southV()), 0, 1e-6);
  EXPECT_NEAR(f->spacingU, 599.7, 0.05);  // 30″ of longitude at 49.8° N
  EXPECT_NEAR(f->spacingV, 926.9, 0.05);  // 30″ of latitude

  // Heights: GDAL's minimum and maximum (which leave no-data out); no-data cells at the lowest.
  GDALRasterBandH band = GDALGetRasterBand(gdal.ds, 1);
  int hasNoData = 0;
  const double noData = GDALGetRasterNoDataValue(band, &hasNoData);
  ASSERT_TRUE(hasNoData);
  double minMax[2];
  ASSERT_EQ(GDALComputeRasterMinMax(band, FALSE, minMax), CE_None);
  EXPECT_EQ(minMax[0], 141);
  EXPECT_EQ(minMax[1], 547);
  EXPECT_NEAR(f->offset, minMax[0], 0.5 * f->scale);
  EXPECT_NEAR(f->offset + 65535 * f->scale, minMax[1], 0.5 * f->scale);
  const std::vector<double> ref = gdal.band1();
  int noDataCells = 0;
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const double r = ref[size_t(j) * size_t(w) + size_t(i)];
      if (r == noData) {
        ++noDataCells;
        ASSERT_EQ(f->code(i, j), 0) << "no-data sample " << i << ", " << j;
      } else {
        ASSERT_NEAR(f->at(i, j), r, 0.5 * f->scale + 1e-9) << "sample " << i << ", " << j;
      }
    }
  EXPECT_GT(noDataCells, 100);  // the land outside Luxembourg
}

TEST_F(TerrainData, TruncatedGeoTiffIsRefusedNamingTheFile) {
  const fs::path dir = tempDir();
  const std::string bytes = readBytes(path("stars/tif/olinda_dem_utm25s.tif")).substr(0, 200);
  const fs::path file = dir / "olinda_200_bytes.tif";
  writeBytes(file, bytes);
  expectOneLineErrorNaming(loadGdal(file.string()), file.string());
  expectOneLineErrorNaming(loadGdalFromMemory(bytes, "olinda_200_bytes.tif"),
                           "olinda_200_bytes.tif");
  fs::remove_all(dir);
}

TEST_F(TerrainData, InMemoryLoadEqualsTheFileLoad) {
  const std::string file = path("stars/tif/olinda_dem_utm25s.tif");
  const Result<HeightField> a = loadGdal(file),
                            b = loadGdalFromMemory(readBytes(file), "olinda.tif");
  ASSERT_TRUE(a.ok()) << a.error().str();
  ASSERT_TRUE(b.ok()) << b.error().str();
  EXPECT_EQ(a->q, b->q);
  EXPECT_EQ(a->originU, b->originU);
  EXPECT_EQ(a->spacingV, b->spacingV);
  EXPECT_EQ(b->source, "olinda.tif");
  // A budget below its 111² samples refuses it before reading.
  const Result<HeightField> small = loadGdalFromMemory(readBytes(file), "olinda.tif", 10000);
  expectOneLineErrorNaming(small, "olinda.tif");
}

TEST(GdalLoader, ReadsAnSrtmTileWrittenByGdal) {
  // N45E006.hgt: 1201² samples 3″ apart, pixel centres on whole degrees at the edges (SRTM's
  // convention, which GDAL's geotransform states as corners half a pixel out).
  const int n = 1201;
  std::vector<double> values(size_t(n) * n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) values[size_t(j) * n + size_t(i)] = 200 + (i * 7 + j * 3) % 1000;
  const double d = 1.0 / 1200;
  const double gt[6] = {6 - 0.5 * d, d, 0, 46 + 0.5 * d, 0, -d};
  const fs::path dir = tempDir();
  const std::string file = (dir / "N45E006.hgt").string();
  writeRaster("SRTMHGT", file, n, n, GDT_Int16, values, gt, 4326);
  const Result<HeightField> f = loadGdal(file);
  ASSERT_TRUE(f.ok()) << f.error().str();
  EXPECT_EQ(f->width, n);
  EXPECT_EQ(f->height, n);
  // Pixel (0, 0)'s centre, 6° E 46° N, from the tile's centre, 6.5° E 45.5° N.
  const double kx = wgs84MetresPerDegreeEast(45.5), ky = wgs84MetresPerDegreeNorth(45.5);
  EXPECT_NEAR(f->originU, -0.5 * kx, 1e-6);
  EXPECT_NEAR(f->originV, 0.5 * ky, 1e-6);
  EXPECT_NEAR(f->spacingU, d * kx, 1e-9);
  EXPECT_NEAR(f->spacingV, d * ky, 1e-9);
  for (size_t k = 0; k < values.size(); k += 997)
    ASSERT_NEAR(f->at(int(k % n), int(k / n)), values[k], 0.5 * f->scale + 1e-9);
  // The same bytes in memory, under the tile's name (the driver reads the position from it).
  const Result<HeightField> m = loadGdalFromMemory(readBytes(file), "N45E006.hgt");
  ASSERT_TRUE(m.ok()) << m.error().str();
  EXPECT_EQ(m->q, f->q);
  EXPECT_EQ(m->originU, f->originU);
  fs::remove_all(dir);
}

TEST(GdalLoader, GeographicTilesInTwoRowsMosaicOnOneLatitude) {
  // Two 1°-high geographic tiles, one above the other, sharing their edge row (as SRTM's do):
  // alone each converts at its own centre latitude (different east–west spacings); together they
  // are placed on one grid at the union's centre latitude, 45°.
  const int n = 11;
  const double d = 0.1;
  const fs::path dir = tempDir();
  std::vector<std::string> files;
  for (int row = 0; row < 2; ++row) {
    std::vector<double> v(size_t(n) * n);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) v[size_t(j) * n + size_t(i)] = 100 + i + 10 * (j + row * (n - 1));
    const double top = 46 - row;  // the tile's northern sample row, degrees
    const double gt[6] = {6 - 0.5 * d, d, 0, top + 0.5 * d, 0, -d};
    files.push_back((dir / ("row" + std::to_string(row) + ".tif")).string());
    writeRaster("GTiff", files.back(), n, n, GDT_Float64, v, gt, 4326);
  }
  std::vector<HeightField> tiles;
  for (const std::string& f : files) tiles.push_back(loadGdal(f).value());
  ASSERT_NE(tiles[0].spacingU, tiles[1].spacingU);  // alone: each at its own latitude
  const Result<HeightField> m = mosaic(tiles);
  ASSERT_TRUE(m.ok()) << m.error().str();
  EXPECT_EQ(m->width, n);
  EXPECT_EQ(m->height, 2 * n - 1);
  EXPECT_NEAR(m->spacingU, d * wgs84MetresPerDegreeEast(45), 1e-6);
  EXPECT_NEAR(m->spacingV, d * wgs84MetresPerDegreeNorth(45), 1e-6);
  for (int j = 0; j < m->height; ++j)
    for (int i = 0; i < m->width; ++i)
      // Quantized twice: each tile's step, then the mosaic's.
      ASSERT_NEAR(m->at(i, j), 100 + i + 10 * j,
                  0.5 * (m->scale + std::max(tiles[0].scale, tiles[1].scale)) + 1e-9)
          << i << ", " << j;
}

TEST(GdalLoader, AppliesTheBandsScaleOffsetAndNoData) {
  const int w = 4, h = 3;
  const std::vector<double> raw = {0, 10, 20, 30, 40, -9999, 60, 70, 80, 90, 100, 110};
  const double gt[6] = {1000, 5, 0, 2000, 0, -5}, noData = -9999;
  const fs::path dir = tempDir();
  const std::string file = (dir / "scaled.tif").string();
  writeRaster("GTiff", file, w, h, GDT_Int16, raw, gt, 32632, &noData, 0.5, 100);
  const Result<HeightField> f = loadGdal(file);
  ASSERT_TRUE(f.ok()) << f.error().str();
  EXPECT_DOUBLE_EQ(f->originU, 1002.5);
  EXPECT_DOUBLE_EQ(f->originV, 1997.5);
  EXPECT_DOUBLE_EQ(f->spacingU, 5);
  EXPECT_DOUBLE_EQ(f->spacingV, 5);
  for (int k = 0; k < w * h; ++k) {
    const double expected = raw[size_t(k)] == noData ? 100 : 100 + 0.5 * raw[size_t(k)];
    EXPECT_NEAR(f->at(k % w, k / w), expected, 0.5 * f->scale + 1e-9) << "sample " << k;
  }
  fs::remove_all(dir);
}

TEST(GdalLoader, RasterWithoutGeotransformGetsUnitSpacingAtTheOrigin) {
  const fs::path dir = tempDir();
  const std::string file = (dir / "plain.tif").string();
  writeRaster("GTiff", file, 3, 2, GDT_Float32, {1, 2, 3, 4, 5, 6}, nullptr, 0);
  const Result<HeightField> f = loadGdal(file);
  ASSERT_TRUE(f.ok()) << f.error().str();
  EXPECT_EQ(f->originU, 0);
  EXPECT_EQ(f->originV, 0);
  EXPECT_EQ(f->spacingU, 1);
  EXPECT_EQ(f->spacingV, 1);
  fs::remove_all(dir);
}

TEST(GdalLoader, RefusesRotatedAndSouthUpRasters) {
  const fs::path dir = tempDir();
  const std::vector<double> v = {1, 2, 3, 4};
  const double rotated[6] = {0, 10, 1, 0, 1, -10}, southUp[6] = {0, 10, 0, 0, 0, 10};
  const std::string a = (dir / "rotated.tif").string(), b = (dir / "south_up.tif").string();
  writeRaster("GTiff", a, 2, 2, GDT_Float32, v, rotated, 32632);
  writeRaster("GTiff", b, 2, 2, GDT_Float32, v, southUp, 32632);
  const Result<HeightField> ra = loadGdal(a), rb = loadGdal(b);
  expectOneLineErrorNaming(ra, a);
  EXPECT_NE(ra.error().message.find("rotated"), std::string::npos) << ra.error().str();
  expectOneLineErrorNaming(rb, b);
  EXPECT_NE(rb.error().message.find("north-up"), std::string::npos) << rb.error().str();
  fs::remove_all(dir);
}

// Malformed input, each refused with one line naming the file (and, for the huge header, before
// anything of its size is allocated: the test would not finish otherwise).
TEST(GdalLoader, RefusesBrokenFilesNamingThem) {
  const fs::path dir = tempDir();
  const fs::path garbage = dir / "garbage.tif";
  static constexpr char kGarbage[] = "II*\0garbage bytes, not a TIFF at all \x01\x02\x03";
  writeBytes(garbage, std::string(kGarbage, sizeof kGarbage - 1));
  expectOneLineErrorNaming(loadGdal(garbage.string()), garbage.string());
  const fs::path huge = dir / "huge.vrt";
  writeBytes(huge,
             "<VRTDataset rasterXSize=\"100000\" rasterYSize=\"100000\">\n"
             "  <VRTRasterBand dataType=\"Float32\" band=\"1\"/>\n"
             "</VRTDataset>\n");
  const Result<HeightField> r = loadGdal(huge.string());
  expectOneLineErrorNaming(r, huge.string());
  EXPECT_NE(r.error().message.find("100000 × 100000"), std::string::npos) << r.error().str();
  // In memory, VRT is not among the drivers at all (it could name other files).
  expectOneLineErrorNaming(loadGdalFromMemory(readBytes(huge), "huge.vrt"), "huge.vrt");
  const std::string missing = (dir / "no_such_file.tif").string();
  expectOneLineErrorNaming(loadGdal(missing), missing);
  expectOneLineErrorNaming(loadHeights(missing, {}), missing);
  expectOneLineErrorNaming(loadGdalFromMemory("", "empty.tif"), "empty.tif");
  fs::remove_all(dir);
}

TEST(PngLoader, SixteenBitRoundTripKeepsEveryCode) {
  // Every code once, 256 × 256.
  std::vector<uint16_t> codes(65536);
  std::iota(codes.begin(), codes.end(), uint16_t(0));
  std::reverse(codes.begin() + 1000, codes.begin() + 30000);  // not just a ramp
  const fs::path dir = tempDir();
  const std::string file = (dir / "heights.PNG").string();  // the extension in any case
  ASSERT_TRUE(texture::writePngGrey16(file, 256, 256, codes.data()).ok());
  const PngPlacement placement{500, 9000, 2, 3, -100, 0.25};
  const Result<HeightField> f = loadHeights(file, placement);
  ASSERT_TRUE(f.ok()) << f.error().str();
  EXPECT_EQ(f->width, 256);
  EXPECT_EQ(f->height, 256);
  EXPECT_EQ(f->q, codes);
  EXPECT_EQ(f->originU, 500);
  EXPECT_EQ(f->originV, 9000);
  EXPECT_EQ(f->spacingU, 2);
  EXPECT_EQ(f->spacingV, 3);
  EXPECT_EQ(f->at(0, 0), -100);
  EXPECT_EQ(f->at(255, 255), -100 + 0.25 * 65535);
  EXPECT_EQ(f->source, file);
  const Result<std::vector<uint8_t>> bytes =
      texture::encodePngGrey16("m.png", 256, 256, codes.data());
  ASSERT_TRUE(bytes.ok());
  const Result<HeightField> m = decodePng16(bytes->data(), bytes->size(), "m.png", placement);
  ASSERT_TRUE(m.ok()) << m.error().str();
  EXPECT_EQ(m->q, codes);
  fs::remove_all(dir);
}

// A PNG chunk: length, type, data, CRC over type and data (PNG spec §5.3).
std::vector<uint8_t> pngChunk(const char* type, const std::vector<uint8_t>& data) {
  const size_t n = data.size();
  std::vector<uint8_t> c(n + 12);
  for (int k = 0; k < 4; ++k) {
    c[size_t(k)] = uint8_t(n >> (24 - 8 * k));
    c[size_t(4 + k)] = uint8_t(type[k]);
  }
  std::copy(data.begin(), data.end(), c.begin() + 8);
  const uLong crc = crc32(0, c.data() + 4, uInt(n + 4));
  for (int k = 0; k < 4; ++k) c[n + 8 + size_t(k)] = uint8_t(crc >> (24 - 8 * k));
  return c;
}

TEST(PngLoader, GammaAndTransparencyChunksDoNotChangeTheCodes) {
  // A tool that tags its height PNG as sRGB-ish (gAMA 1/2.2) or marks a code transparent must not
  // have libpng convert or compose the heights.
  std::vector<uint16_t> codes(64 * 64);
  for (size_t k = 0; k < codes.size(); ++k) codes[k] = uint16_t(k * 16 + 5);
  Result<std::vector<uint8_t>> png = texture::encodePngGrey16("t.png", 64, 64, codes.data());
  ASSERT_TRUE(png.ok());
  std::vector<uint8_t> bytes = png.value();
  const size_t afterIhdr = 8 + 12 + 13;
  std::vector<uint8_t> extra = pngChunk("gAMA", {0, 0, 0xB1, 0x8F});  // 45455: 1/2.2
  const std::vector<uint8_t> trns = pngChunk("tRNS", {0, 5});         // code 5 transparent
  extra.insert(extra.end(), trns.begin(), trns.end());
  bytes.insert(bytes.begin() + afterIhdr, extra.begin(), extra.end());
  const Result<HeightField> f = decodePng16(bytes.data(), bytes.size(), "t.png", {});
  ASSERT_TRUE(f.ok()) << f.error().str();
  EXPECT_EQ(f->q, codes);
}

TEST(PngLoader, RefusesBrokenOrUnsuitablePngsNamingThem) {
  const fs::path dir = tempDir();
  const uint16_t one = 7;
  const std::string tiny = (dir / "one_pixel.png").string();
  ASSERT_TRUE(texture::writePngGrey16(tiny, 1, 1, &one).ok());
  expectOneLineErrorNaming(loadPng16(tiny, {}), tiny);
  const std::string colour = (dir / "colour.png").string();
  const std::vector<uint8_t> rgb(4 * 4 * 3, 100);
  ASSERT_TRUE(texture::writePng(colour, 4, 4, 3, rgb.data()).ok());
  expectOneLineErrorNaming(loadPng16(colour, {}), colour);
  const std::string missing = (dir / "missing.png").string();
  expectOneLineErrorNaming(loadHeights(missing, {}), missing);
  const std::string garbage = "\x89PNG\r\n\x1a\n and then nothing that libpng can read";
  expectOneLineErrorNaming(decodePng16(garbage.data(), garbage.size(), "g.png", {}), "g.png");
  // A placement that places nothing.
  std::vector<uint16_t> codes(16, 3);
  const std::string good = (dir / "good.png").string();
  ASSERT_TRUE(texture::writePngGrey16(good, 4, 4, codes.data()).ok());
  expectOneLineErrorNaming(loadPng16(good, {0, 0, 0, 1, 0, 1}), good);
  expectOneLineErrorNaming(loadPng16(good, {0, 0, 1, 1, 0, NAN}), good);
  fs::remove_all(dir);
}

// A part of `f`, columns i0 … i0 + w − 1 and rows j0 … j0 + h − 1, requantized on its own (as a
// separate file would be) and placed where it lies in `f`.
HeightField tileOf(const HeightField& f, int i0, int j0, int w, int h, const std::string& name) {
  std::vector<double> v(size_t(w) * size_t(h));
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) v[size_t(j) * size_t(w) + size_t(i)] = f.at(i0 + i, j0 + j);
  Result<HeightField> t = quantize(v, w, h, name);
  EXPECT_TRUE(t.ok());
  t->spacingU = f.spacingU;
  t->spacingV = f.spacingV;
  t->originU = f.originU + i0 * f.spacingU;
  t->originV = f.originV - j0 * f.spacingV;
  return std::move(t).value();
}

TEST(Mosaic, TwoByTwoTilesSharingAnEdgeRowMergeBackToTheTable) {
  const Result<HeightField> whole = generateFractal(65, 30, 1200, 29);
  ASSERT_TRUE(whole.ok());
  // SRTM's layout: neighbours repeat the shared row and column (sample 32 is in both halves).
  std::vector<HeightField> tiles = {
      tileOf(whole.value(), 32, 32, 33, 33, "se"), tileOf(whole.value(), 0, 0, 33, 33, "nw"),
      tileOf(whole.value(), 32, 0, 33, 33, "ne"), tileOf(whole.value(), 0, 32, 33, 33, "sw")};
  const Result<HeightField> m = mosaic(tiles);
  ASSERT_TRUE(m.ok()) << m.error().str();
  EXPECT_EQ(m->width, 65);
  EXPECT_EQ(m->height, 65);
  EXPECT_NEAR(m->originU, whole->originU, 1e-9);
  EXPECT_NEAR(m->originV, whole->originV, 1e-9);
  EXPECT_EQ(m->spacingU, 30);
  double tileStep = 0;
  for (const HeightField& t : tiles) tileStep = std::max(tileStep, t.scale);
  // Each tile within half its step of the table, the mosaic within half its own of the tile.
  const double tolerance = 0.5 * tileStep + 0.5 * m->scale + 1e-9;
  for (int j = 0; j < 65; ++j)
    for (int i = 0; i < 65; ++i)
      ASSERT_NEAR(m->at(i, j), whole->at(i, j), tolerance) << "sample " << i << ", " << j;
}

TEST(Mosaic, RefusesTilesOffTheGridOrDisagreeingNamingBoth) {
  const Result<HeightField> whole = generateFractal(33, 30, 500, 7);
  ASSERT_TRUE(whole.ok());
  const HeightField west = tileOf(whole.value(), 0, 0, 17, 33, "west.tif");
  HeightField east = tileOf(whole.value(), 16, 0, 17, 33, "east.tif");
  auto expectNamesBoth = [](const Result<HeightField>& r, const char* what) {
    ASSERT_FALSE(r.ok()) << what;
    EXPECT_NE(r.error().str().find("west.tif"), std::string::npos) << r.error().str();
    EXPECT_NE(r.error().str().find("east.tif"), std::string::npos) << r.error().str();
    EXPECT_EQ(r.error().str().find('\n'), std::string::npos) << r.error().str();
  };
  HeightField wrongSpacing = east;
  wrongSpacing.spacingU *= 1.001;
  expectNamesBoth(mosaic({west, wrongSpacing}), "spacing");
  HeightField offGrid = east;
  offGrid.originU += 0.5 * offGrid.spacingU;
  expectNamesBoth(mosaic({west, offGrid}), "half a step off");
  HeightField raised = east;
  raised.offset += 10;  // metres: the shared column disagrees
  expectNamesBoth(mosaic({west, raised}), "overlap");
  // A hair off the grid (within 1/1000 of a step) it merges.
  HeightField nearly = east;
  nearly.originU += 1e-4 * nearly.spacingU;
  EXPECT_TRUE(mosaic({west, nearly}).ok());
}

TEST(Mosaic, UncoveredSamplesTakeTheLowestHeight) {
  const Result<HeightField> whole = generateFractal(33, 10, 300, 3);
  ASSERT_TRUE(whole.ok());
  // Two diagonal corners: the other two quarters are covered by no tile.
  const Result<HeightField> m = mosaic(
      {tileOf(whole.value(), 0, 0, 10, 10, "a"), tileOf(whole.value(), 23, 23, 10, 10, "b")});
  ASSERT_TRUE(m.ok()) << m.error().str();
  EXPECT_EQ(m->width, 33);
  EXPECT_EQ(m->code(32, 0), 0);
  EXPECT_EQ(m->code(0, 32), 0);
  EXPECT_EQ(m->code(16, 16), 0);
  double lowest = 1e9;
  for (int j = 0; j < 33; ++j)
    for (int i = 0; i < 33; ++i) lowest = std::min(lowest, m->at(i, j));
  EXPECT_EQ(m->at(32, 0), lowest);
}

TEST(Mosaic, RefusesAnUnionBeyondTheLargestTable) {
  const Result<HeightField> whole = generateFractal(9, 10, 100, 1);
  ASSERT_TRUE(whole.ok());
  HeightField far = whole.value();
  far.originU += 20000 * far.spacingU;
  const Result<HeightField> m = mosaic({whole.value(), far});
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().message.find("beyond the limit"), std::string::npos) << m.error().str();
}

}  // namespace
}  // namespace sv::formats
