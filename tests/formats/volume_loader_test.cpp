// Volume files (loadVolume, parseVolume): NIfTI-1 and NRRD read with their exact 8- and 16-bit
// values, signed data offset, wider and float data quantized over their range, scl_slope applied,
// either byte order, gzip; sizes checked before allocating, truncation and unsupported variants
// named; the real Colin 27 head of Debian's mricron-data when scripts/lib.sh has unpacked it.
// OpenVDB files written here by OpenVDB itself: densified over their active voxels with the
// grid's values (background elsewhere), the chosen grid, the spacing; broken and unreadable ones
// refused by name.
#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <zlib.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "formats/formats_test_util.h"
#include "support/temp_dir.h"

namespace sv::formats {
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
  for (int i = 0; i < 60; ++i)
    EXPECT_EQ(g->value(g->codes[size_t(i)]), 2.0f * float(i * 100 - 3000) - 1);
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
  const std::string header =
      "NRRD0004\n# comment\ntype: uchar\ndimension: 3\nsizes: 3 4 5\n"
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
      "(0,0,2)\nendian: little\nencoding: gzip\n\n" +
          gzip(wide),
      "b.nrrd", false);
  ASSERT_TRUE(z.ok()) << z.error().str();
  EXPECT_EQ(z->spacing.z, 2.0f);
  for (int i = 0; i < 60; ++i) EXPECT_EQ(z->value(z->codes[size_t(i)]), float(i - 30));
  // Detached: a .nhdr naming its raw file beside it.
  const sv::tests::TempDir temp;
  const std::filesystem::path& dir = temp.dir();
  std::ofstream((dir / "d.raw").string(), std::ios::binary) << data;
  std::ofstream((dir / "d.nhdr").string(), std::ios::binary)
      << "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 3 4 5\nencoding: raw\ndata file: d.raw\n";
  Result<VolumeGrid> d = loadVolume((dir / "d.nhdr").string());
  ASSERT_TRUE(d.ok()) << d.error().str();
  EXPECT_EQ(d->codes, g->codes);
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
  refused("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 3 4 5\nencoding: bzip2\n\n" + data, "d.nrrd",
          "encoding 'bzip2'");
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

// The bytes of an OpenVDB file of `grids` as io::File writes it (with its grid offsets, compressed
// as OpenVDB chooses).
std::string vdbBytes(const openvdb::GridCPtrVec& grids, const openvdb::MetaMap& meta = {}) {
  openvdb::initialize();
  const std::string path = sv::tests::processTemp().path("grids.vdb");
  openvdb::io::File(path).write(grids, meta);
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  std::filesystem::remove(path);
  return bytes.str();
}

// A float grid of background 0 and voxel size 0.5 whose active voxels are the box
// [2, 5] × [−1, 1] × [10, 12], valued 1 + i + 10·j + 100·k, but for (3, 0, 11), inactive (0).
openvdb::FloatGrid::Ptr boxGrid(const std::string& name) {
  openvdb::FloatGrid::Ptr g = openvdb::FloatGrid::create(0.0f);
  g->setName(name);
  g->setTransform(openvdb::math::Transform::createLinearTransform(0.5));
  for (int k = 10; k <= 12; ++k)
    for (int j = -1; j <= 1; ++j)
      for (int i = 2; i <= 5; ++i) g->tree().setValueOn({i, j, k}, float(1 + i + 10 * j + 100 * k));
  g->tree().setValueOff({3, 0, 11}, 0.0f);
  return g;
}

TEST(VolumeFiles, OpenVdbGridIsDensifiedOverItsActiveVoxels) {
  // "density" is chosen over an earlier scalar grid and a vector grid.
  openvdb::FloatGrid::Ptr other = openvdb::FloatGrid::create(7.0f);
  other->setName("aaa");
  other->tree().setValueOn({0, 0, 0}, 8.0f);
  openvdb::Vec3SGrid::Ptr velocity = openvdb::Vec3SGrid::create();
  velocity->setName("vel");
  velocity->tree().setValueOn({1, 2, 3}, openvdb::Vec3s(1, 0, 0));
  const std::string bytes = vdbBytes({other, boxGrid("density"), velocity});
  // Through a file, as a scene names it.
  const sv::tests::TempDir dir;
  Result<VolumeGrid> g = loadVolume(dir.write("box.vdb", bytes));
  ASSERT_TRUE(g.ok()) << g.error().str();
  EXPECT_EQ(g->nx, 4);
  EXPECT_EQ(g->ny, 3);
  EXPECT_EQ(g->nz, 3);
  EXPECT_EQ(g->spacing.x, 0.5f);
  EXPECT_EQ(g->spacing.z, 0.5f);
  // Sample (0, 0, 0) is the least active voxel, (2, −1, 10); floats are quantized over their
  // range 0 … 1226.
  const double step = 1226.0 / 65535;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 4; ++i) {
        const bool off = i == 1 && j == 1 && k == 1;
        const double want = off ? 0 : 1 + (i + 2) + 10 * (j - 1) + 100 * (k + 10);
        EXPECT_NEAR(g->value(g->codes[g->at(i, j, k)]), want, step / 2 + 1e-3) << i << j << k;
      }
  // In memory, with parseVolume: the same grid.
  Result<VolumeGrid> m = parseVolume(bytes, "box.vdb", false);
  ASSERT_TRUE(m.ok()) << m.error().str();
  EXPECT_EQ(m->codes, g->codes);
}

TEST(VolumeFiles, OpenVdbFogSphereDoubleAndIntegerGrids) {
  // A level set sphere (built on OpenVDB's threads, before the reader's fork) as a fog volume:
  // 1 inside, 0 (the background) outside its narrow band, on the sphere's voxels of 0.25.
  openvdb::FloatGrid::Ptr sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
      2.0f, openvdb::Vec3f(1, 0, 0), 0.25f);
  openvdb::tools::sdfToFogVolume(*sphere);
  sphere->setName("cloud");
  openvdb::CoordBBox box = sphere->evalActiveVoxelBoundingBox();
  Result<VolumeGrid> g = parseVolume(vdbBytes({sphere}), "sphere.vdb", false);
  ASSERT_TRUE(g.ok()) << g.error().str();
  EXPECT_EQ(g->nx, box.dim().x());
  EXPECT_EQ(g->ny, box.dim().y());
  EXPECT_EQ(g->nz, box.dim().z());
  EXPECT_EQ(g->spacing.y, 0.25f);
  EXPECT_NEAR(g->value(g->codes[g->at(g->nx / 2, g->ny / 2, g->nz / 2)]), 1, 1e-4);  // the centre
  EXPECT_EQ(g->value(g->codes[g->at(0, 0, 0)]), 0);  // a corner of the box, outside the sphere
  // A double grid with a non-uniform (linear) scale; an int32 grid's values.
  openvdb::DoubleGrid::Ptr wide = openvdb::DoubleGrid::create(-1.0);
  openvdb::Mat4R scale = openvdb::Mat4R::identity();
  scale.preScale(openvdb::Vec3d(0.5, 1, 2));
  scale.postTranslate(openvdb::Vec3d(3, 4, 5));
  wide->setTransform(openvdb::math::Transform::createLinearTransform(scale));
  for (int i = 0; i < 3; ++i) wide->tree().setValueOn({i, i, i}, 0.125 * i);
  Result<VolumeGrid> d = parseVolume(vdbBytes({wide}), "double.vdb", false);
  ASSERT_TRUE(d.ok()) << d.error().str();
  EXPECT_EQ(d->nx, 3);
  EXPECT_EQ(d->spacing.x, 0.5f);
  EXPECT_EQ(d->spacing.y, 1.0f);
  EXPECT_EQ(d->spacing.z, 2.0f);
  EXPECT_NEAR(d->value(d->codes[d->at(2, 2, 2)]), 0.25, 1e-4);
  EXPECT_NEAR(d->value(d->codes[d->at(0, 2, 1)]), -1, 1e-4);  // the background between them
  openvdb::Int32Grid::Ptr counts = openvdb::Int32Grid::create(0);
  counts->tree().setValueOn({0, 0, 0}, 65535);
  counts->tree().setValueOn({1, 0, 0}, 1000);  // a sheet one voxel thick: widened to 2 samples
  Result<VolumeGrid> c = parseVolume(vdbBytes({counts}), "int.vdb", false);
  ASSERT_TRUE(c.ok()) << c.error().str();
  EXPECT_EQ(c->nx, 2);
  EXPECT_EQ(c->ny, 2);
  EXPECT_EQ(c->nz, 2);
  EXPECT_EQ(c->value(c->codes[c->at(0, 0, 0)]), 65535.0f);
  EXPECT_EQ(c->value(c->codes[c->at(1, 0, 0)]), 1000.0f);
  EXPECT_EQ(c->value(c->codes[c->at(1, 1, 1)]), 0.0f);
}

TEST(VolumeFiles, BadOpenVdbFilesAreRefusedByName) {
  auto refused = [](const std::string& bytes, const std::string& name, const std::string& part,
                    size_t maxSamples = kMaxVolumeSamples) {
    const auto start = std::chrono::steady_clock::now();
    Result<VolumeGrid> g = parseVolume(bytes, name, false, maxSamples);
    ASSERT_FALSE(g.ok()) << part;
    EXPECT_NE(g.error().str().find(part), std::string::npos) << g.error().str();
    EXPECT_EQ(g.error().str().rfind(name + ": ", 0), 0u) << g.error().str();
    EXPECT_EQ(g.error().str().find('\n'), std::string::npos) << g.error().str();
    // Refused in well under the child's time limit: nothing was densified.
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(4)) << part;
  };
  const std::string box = vdbBytes({boxGrid("density")});
  // Truncated: OpenVDB's own exception, or (its header's reads are unchecked) no grid found.
  refused(box.substr(0, box.size() / 2), "half.vdb", "OpenVDB: ");
  refused(box.substr(0, 40), "header.vdb", "OpenVDB finds no grid in it");
  std::string garbage = box.substr(0, 8);
  for (int i = 0; i < 4000; ++i) garbage += char((i * 7919) >> 3);
  refused(garbage, "garbage.vdb", "OpenVDB finds no grid in it");
  refused("P6 3 4 255\n", "image.vdb", "not an OpenVDB file");
  // Two voxels 100 000 apart: a box far beyond the limits, refused from its size alone (and the
  // grid's name kept to one line).
  openvdb::FloatGrid::Ptr far = openvdb::FloatGrid::create(0.0f);
  far->setName("far\naway");
  far->tree().setValueOn({0, 0, 0}, 1.0f);
  far->tree().setValueOn({100000, 0, 0}, 1.0f);
  refused(vdbBytes({far}), "far.vdb",
          "grid 'far?away': 100001 × 2 × 2 samples: each side must be 2");
  openvdb::FloatGrid::Ptr large = openvdb::FloatGrid::create(0.0f);
  large->tree().setValueOn({0, 0, 0}, 1.0f);
  large->tree().setValueOn({2047, 2047, 2047}, 1.0f);
  refused(vdbBytes({large}), "large.vdb", "2048 × 2048 × 2048 samples: more than");
  refused(box, "budget.vdb", "4 × 3 × 3 samples: more than 20", 20);
  openvdb::Vec3SGrid::Ptr velocity = openvdb::Vec3SGrid::create();
  velocity->setName("vel");
  velocity->tree().setValueOn({1, 2, 3}, openvdb::Vec3s(1, 0, 0));
  refused(vdbBytes({velocity}), "vectors.vdb",
          "no scalar grid (float, double or int32): it holds 'vel' (vec3s)");
  openvdb::FloatGrid::Ptr empty = openvdb::FloatGrid::create(0.0f);
  empty->setName("nothing");
  refused(vdbBytes({empty}), "empty.vdb", "grid 'nothing' has no active voxels");
  openvdb::FloatGrid::Ptr frustum = boxGrid("f");
  frustum->setTransform(openvdb::math::Transform::createFrustumTransform(
      openvdb::BBoxd(openvdb::Vec3d(0, 0, 0), openvdb::Vec3d(10, 10, 10)), 0.5, 2));
  refused(vdbBytes({frustum}), "frustum.vdb", "grid 'f' has a non-linear transform");
  // A file-level string claiming 3.75 GiB: OpenVDB allocates it, and meets the reader's memory
  // limit (1/4 GiB for so small a budget).
  openvdb::MetaMap meta;
  meta.insertMeta("note", openvdb::StringMetadata("synthvis-note"));
  std::string hungry = vdbBytes({boxGrid("density")}, meta);
  const uint32_t huge = 0xF0000000u;
  ASSERT_NE(hungry.find("synthvis-note"), std::string::npos);
  std::memcpy(&hungry[hungry.find("synthvis-note") - 4], &huge, 4);
  refused(hungry, "hungry.vdb", "out of memory", 1000);
  Result<VolumeGrid> missing = loadVolume("/nonexistent/cloud.vdb");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().str().find("/nonexistent/cloud.vdb: cannot open"), std::string::npos)
      << missing.error().str();
}

TEST(VolumeFiles, TheColin27HeadOfDebiansMricronData) {
  const std::string path = SV_VOLUME_DATA_DIR "/ch2.nii.gz";
  if (!std::filesystem::exists(path))
    GTEST_SKIP() << path << " not unpacked (scripts/lib.sh sv_data)";
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
}  // namespace sv::formats
