// Volume files (loadVolume, parseVolume): NIfTI-1 and NRRD read with their exact 8- and 16-bit
// values, signed data offset, wider and float data quantized over their range, scl_slope applied,
// either byte order, gzip; sizes checked before allocating, truncation and unsupported variants
// named; the real Colin 27 head of Debian's mricron-data when scripts/lib.sh has unpacked it.
#include <gtest/gtest.h>

#include <zlib.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "synthvis/scene.h"

namespace sv::scene {
namespace {

// A NIfTI-1 single file: dims, datatype and bits, the samples' bytes, the value scaling.
std::string nifti(int nx, int ny, int nz, int16_t datatype, int16_t bitpix, const std::string& data,
                  float slope = 0, float inter = 0, bool big = false) {
  std::string h(352, '\0');
  auto put = [&](size_t at, const void* v, size_t n) {
    std::memcpy(&h[at], v, n);
    if (big) std::reverse(h.begin() + long(at), h.begin() + long(at + n));
  };
  const int32_t size = 348;
  put(0, &size, 4);
  const int16_t dim[8] = {3, int16_t(nx), int16_t(ny), int16_t(nz), 1, 1, 1, 1};
  for (int i = 0; i < 8; ++i) put(40 + 2 * size_t(i), &dim[i], 2);
  put(70, &datatype, 2);
  put(72, &bitpix, 2);
  const float pixdim[4] = {1, 0.5f, 0.75f, 1.25f};
  for (int i = 0; i < 4; ++i) put(76 + 4 * size_t(i), &pixdim[i], 4);
  const float offset = 352;
  put(108, &offset, 4);
  put(112, &slope, 4);
  put(116, &inter, 4);
  std::memcpy(&h[344], "n+1", 4);
  return h + data;
}

std::string gzip(const std::string& bytes) {
  z_stream z{};
  deflateInit2(&z, 6, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY);
  std::string out(deflateBound(&z, uLong(bytes.size())), '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  z.avail_in = uInt(bytes.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = uInt(out.size());
  deflate(&z, Z_FINISH);
  out.resize(z.total_out);
  deflateEnd(&z);
  return out;
}

std::string bytesOf(int n, uint8_t (*f)(int)) {
  std::string s;
  for (int i = 0; i < n; ++i) s += char(f(i));
  return s;
}

TEST(VolumeFiles, NiftiEightBitValuesAndSpacingAreExact) {
  const std::string data = bytesOf(60, [](int i) { return uint8_t(i * 4); });
  Result<VolumeGrid> g = parseVolume(nifti(3, 4, 5, 2, 8, data), "a.nii", false);
  ASSERT_TRUE(g.ok()) << g.error().str();
  EXPECT_EQ(g->nx, 3);
  EXPECT_EQ(g->ny, 4);
  EXPECT_EQ(g->nz, 5);
  EXPECT_EQ(g->spacing.x, 0.5f);
  EXPECT_EQ(g->spacing.y, 0.75f);
  EXPECT_EQ(g->spacing.z, 1.25f);
  for (int i = 0; i < 60; ++i) EXPECT_EQ(g->value(g->codes[size_t(i)]), float(i * 4));
  // The same gzipped (.nii.gz).
  Result<VolumeGrid> z = parseVolume(gzip(nifti(3, 4, 5, 2, 8, data)), "a.nii.gz", false);
  ASSERT_TRUE(z.ok()) << z.error().str();
  EXPECT_EQ(z->codes, g->codes);
}

TEST(VolumeFiles, NiftiSignedBigEndianDataWithItsScaling) {
  std::string data;
  for (int i = 0; i < 60; ++i) {
    const int16_t v = int16_t(i * 100 - 3000);
    data += char(uint16_t(v) >> 8);
    data += char(uint16_t(v) & 0xFF);
  }
  Result<VolumeGrid> g = parseVolume(nifti(3, 4, 5, 4, 16, data, 2, -1, true), "b.nii", false);
  ASSERT_TRUE(g.ok()) << g.error().str();
  for (int i = 0; i < 60; ++i) EXPECT_EQ(g->value(g->codes[size_t(i)]), 2.0f * float(i * 100 - 3000) - 1);
  // A negative slope reverses the codes and keeps the values.
  Result<VolumeGrid> n = parseVolume(nifti(3, 4, 5, 4, 16, data, -0.5f, 0, true), "c.nii", false);
  ASSERT_TRUE(n.ok()) << n.error().str();
  EXPECT_GT(n->scale, 0);
  for (int i = 0; i < 60; ++i)
    EXPECT_NEAR(n->value(n->codes[size_t(i)]), -0.5 * (i * 100 - 3000), 1e-2);
}

TEST(VolumeFiles, FloatDataIsQuantizedOverItsRange) {
  std::string data;
  for (int i = 0; i < 60; ++i) {
    const float v = float(i) * 0.25f - 2;
    data.append(reinterpret_cast<const char*>(&v), 4);
  }
  Result<VolumeGrid> g = parseVolume(nifti(3, 4, 5, 16, 32, data), "f.nii", false);
  ASSERT_TRUE(g.ok()) << g.error().str();
  for (int i = 0; i < 60; ++i)
    EXPECT_NEAR(g->value(g->codes[size_t(i)]), i * 0.25 - 2, 14.75 / 65535);
}

TEST(VolumeFiles, NrrdAttachedDetachedAndGzip) {
  const std::string data = bytesOf(60, [](int i) { return uint8_t(200 - i); });
  const std::string header = "NRRD0004\n# comment\ntype: uchar\ndimension: 3\nsizes: 3 4 5\n"
                             "spacings: 1 2 3\nkey:=value\nencoding: raw\n\n";
  Result<VolumeGrid> g = parseVolume(header + data, "a.nrrd", false);
  ASSERT_TRUE(g.ok()) << g.error().str();
  EXPECT_EQ(g->spacing.y, 2.0f);
  for (int i = 0; i < 60; ++i) EXPECT_EQ(g->codes[size_t(i)], 200 - i);
  // 16-bit little-endian, gzip, spacings from space directions.
  std::string wide;
  for (int i = 0; i < 60; ++i) {
    const int16_t v = int16_t(i - 30);
    wide.append(reinterpret_cast<const char*>(&v), 2);
  }
  Result<VolumeGrid> z = parseVolume(
      "NRRD0005\ntype: short\ndimension: 3\nsizes: 3 4 5\nspace directions: (0.5,0,0) (0,0.5,0) "
      "(0,0,2)\nendian: little\nencoding: gzip\n\n" + gzip(wide),
      "b.nrrd", false);
  ASSERT_TRUE(z.ok()) << z.error().str();
  EXPECT_EQ(z->spacing.z, 2.0f);
  for (int i = 0; i < 60; ++i) EXPECT_EQ(z->value(z->codes[size_t(i)]), float(i - 30));
  // Detached: a .nhdr naming its raw file beside it.
  const auto dir = std::filesystem::temp_directory_path() / "sv_volume_test";
  std::filesystem::create_directories(dir);
  std::ofstream((dir / "d.raw").string(), std::ios::binary) << data;
  std::ofstream((dir / "d.nhdr").string(), std::ios::binary)
      << "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 3 4 5\nencoding: raw\ndata file: d.raw\n";
  Result<VolumeGrid> d = loadVolume((dir / "d.nhdr").string());
  ASSERT_TRUE(d.ok()) << d.error().str();
  EXPECT_EQ(d->codes, g->codes);
  std::filesystem::remove_all(dir);
}

TEST(VolumeFiles, BadFilesAreRefusedByNameBeforeAllocating) {
  auto refused = [](const std::string& bytes, const std::string& name, const std::string& part) {
    Result<VolumeGrid> g = parseVolume(bytes, name, false);
    ASSERT_FALSE(g.ok()) << part;
    EXPECT_NE(g.error().str().find(part), std::string::npos) << g.error().str();
    EXPECT_NE(g.error().str().find(name), std::string::npos) << g.error().str();
  };
  const std::string data(60, '\1');
  refused(nifti(3, 4, 5, 2, 8, data).substr(0, 300), "t.nii", "truncated");
  refused(nifti(3, 4, 5, 2, 8, data).substr(0, 380), "t.nii", "truncated");
  // A header claiming 8192³ samples of a few bytes: refused, not allocated.
  refused(nifti(8192, 8192, 8192, 2, 8, data), "big.nii", "more than");
  refused(nifti(20000, 4, 5, 2, 8, data), "side.nii", "each side");
  refused(nifti(1024, 1024, 512, 2, 8, data), "short.nii", "truncated");
  refused(gzip(nifti(1024, 1024, 512, 2, 8, data)), "short.nii.gz", "truncated");
  refused(nifti(3, 4, 5, 128, 24, data), "rgb.nii", "datatype 128");
  std::string series = nifti(3, 4, 5, 2, 8, data);
  series[40] = 4, series[48] = 7;  // dim[0] = 4, dim[4] = 7
  refused(series, "series.nii", "a series of 7 volumes");
  std::string magic = nifti(3, 4, 5, 2, 8, data);
  std::memcpy(&magic[344], "ni1", 4);
  refused(magic, "pair.nii", ".hdr/.img");
  refused("NRRD0004\ntype: uchar\ndimension: 2\nsizes: 3 4\nencoding: raw\n\n" + data, "d.nrrd",
          "dimension is 2");
  refused("NRRD0004\ntype: block\ndimension: 3\nsizes: 3 4 5\nencoding: raw\n\n" + data, "d.nrrd",
          "type 'block'");
  refused("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 3 4 5\nencoding: bzip2\n\n" + data,
          "d.nrrd", "encoding 'bzip2'");
  refused("NRRD0004\ntype: short\ndimension: 3\nsizes: 3 4 5\nencoding: raw\n\n" + data, "d.nrrd",
          "endian");
  refused("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 3 4 5\nencoding: raw\n\n" + data.substr(10),
          "d.nrrd", "truncated");
  refused("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 3 4 5\nencoding: raw\ndata file: x.raw\n\n",
          "d.nhdr", "is not opened here");
  refused("NRRD0004\ntype: uchar", "d.nrrd", "no end");
  refused("NRRD0004\ntype: uchar\n", "d.nrrd", "dimension is missing");
  refused("P6 3 4 255\n", "d.nrrd", "not a NRRD");
}

TEST(VolumeFiles, TheColin27HeadOfDebiansMricronData) {
  const std::string path = SV_VOLUME_DATA_DIR "/ch2.nii.gz";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not unpacked (scripts/lib.sh sv_data)";
  Result<VolumeGrid> g = loadVolume(path);
  ASSERT_TRUE(g.ok()) << g.error().str();
  EXPECT_EQ(g->nx, 181);
  EXPECT_EQ(g->ny, 217);
  EXPECT_EQ(g->nz, 181);
  EXPECT_EQ(g->spacing.x, 1.0f);
  EXPECT_EQ(g->scale, 1.0f);
  EXPECT_EQ(g->offset, 0.0f);
  EXPECT_EQ(*std::max_element(g->codes.begin(), g->codes.end()), 254);  // its brightest sample
}

}  // namespace
}  // namespace sv::scene
