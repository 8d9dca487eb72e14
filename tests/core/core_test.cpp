#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "core/check.h"
#include "core/streaming.h"
#include "core/thread_pool.h"
#include "support/temp_dir.h"
#include "synthvis/files.h"
#include "synthvis/frame_stats.h"
#include "synthvis/math.h"

namespace sv {
namespace {

TEST(ThreadPool, RunsEveryItemExactlyOnceForAnyThreadCount) {
  for (int threads : {1, 2, 3, 8}) {
    core::ThreadPool pool(threads);
    for (size_t count : {size_t(0), size_t(1), size_t(7), size_t(1000)}) {
      std::vector<std::atomic<int>> hits(count);
      pool.parallelFor(count, [&](size_t i, int worker) {
        EXPECT_GE(worker, 0);
        EXPECT_LT(worker, threads);
        hits[i].fetch_add(1);
      });
      for (size_t i = 0; i < count; ++i) EXPECT_EQ(hits[i].load(), 1) << threads << " " << i;
    }
  }
}

// Binning's record copy: element k takes src[order[k]] whole, or only its first `prefix` bytes
// with the rest of dst untouched (the streaming path: 16-byte multiples, aligned); elements of
// other sizes are copied plainly, and whole when the prefix is no multiple of 16.
TEST(Streaming, GatherCopiesWholeRecordsOrTheirPrefixInTheGivenOrder) {
  struct alignas(64) Record {
    uint8_t bytes[128];
  };
  std::vector<Record> src(5);
  for (size_t r = 0; r < src.size(); ++r)
    for (size_t b = 0; b < sizeof(Record); ++b) src[r].bytes[b] = uint8_t(r * 31 + b);
  const uint32_t order[] = {3, 0, 4, 1};
  for (size_t prefix : {sizeof(Record), size_t(64), size_t(16)}) {
    std::vector<Record> dst(4);
    for (Record& d : dst) std::fill(std::begin(d.bytes), std::end(d.bytes), uint8_t(0xEE));
    core::gatherStreaming(dst.data(), src.data(), order, 4, prefix);
    for (size_t k = 0; k < 4; ++k)
      for (size_t b = 0; b < sizeof(Record); ++b)
        ASSERT_EQ(dst[k].bytes[b], b < prefix ? src[order[k]].bytes[b] : 0xEE)
            << "prefix " << prefix << " element " << k << " byte " << b;
  }
  // Elements of 12 bytes (not whole 16-byte units) take the plain path; a prefix that is not a
  // multiple of 16 copies them whole.
  struct Small {
    uint32_t v[3];
  };
  const std::vector<Small> from = {{{1, 2, 3}}, {{4, 5, 6}}};
  std::vector<Small> to(2, Small{{9, 9, 9}});
  const uint32_t swap[] = {1, 0};
  core::gatherStreaming(to.data(), from.data(), swap, 2, 8);
  EXPECT_EQ(to[0].v[2], 6u);
  EXPECT_EQ(to[1].v[0], 1u);
}

// A finite non-zero vector of any size has a unit direction: a length that overflows (1e30: its
// square is beyond float) or underflows (1e-25) must not give a zero or infinite vector (a fuzzed
// OpenFlight light faced 1e30-long normals and got direction 0, which validation refuses).
TEST(Vec3, NormalizeGivesAUnitVectorForAnyFiniteNonZeroVector) {
  for (float s : {1.0f, 1e30f, 3e38f, 1e-20f, 1e-25f, 1e-40f}) {
    for (Vec3 v : {Vec3{s, 0, 0}, Vec3{s, -s, s}, Vec3{0, 0, -s}, Vec3{s, s * 0.5f, 0}}) {
      const Vec3 n = normalize(v);
      EXPECT_TRUE(isFinite(n)) << s;
      EXPECT_NEAR(length(n), 1.0f, 1e-6f) << s;
      EXPECT_GT(dot(n, v), 0.0f) << s;  // the same direction
    }
  }
  // The common case keeps its bits: a · (1 / |a|).
  const Vec3 a{3, -4, 12};
  const Vec3 n = normalize(a);
  const float inv = 1.0f / length(a);
  EXPECT_EQ(n, (Vec3{a.x * inv, a.y * inv, a.z * inv}));
  // Zero and non-finite vectors come back unchanged.
  EXPECT_EQ(normalize(Vec3{0, 0, 0}), (Vec3{0, 0, 0}));
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_EQ(normalize(Vec3{inf, 0, 0}), (Vec3{inf, 0, 0}));
  EXPECT_FALSE(isFinite(normalize(Vec3{std::nanf(""), 1, 0})));
}

TEST(Mat4, NormalMatrixKeepsNormalsPerpendicularUnderNonUniformScale) {
  const Mat4 m = Mat4::rotation({1, 2, 3}, 0.7f) * Mat4::scaling({3, 0.5f, 2});
  const Vec3 tangent{1, -1, 0}, normal{1, 1, 0.5f};  // perpendicular: 1 − 1 + 0 = 0
  const Vec3 t = m.transformDirection(tangent);
  const Vec3 n = m.normalMatrix().transformDirection(normal);
  EXPECT_NEAR(dot(t, n), 0.0f, 1e-5f);
}

TEST(Mat4, PerspectiveMapsNearAndFarToMinusOneAndOne) {
  const Mat4 p = Mat4::perspective(1.0f, 1.5f, 0.5f, 20.0f);
  const Vec4 nearPt = p * Vec4{0, 0, -0.5f, 1}, farPt = p * Vec4{0, 0, -20.0f, 1};
  EXPECT_NEAR(nearPt.z / nearPt.w, -1.0f, 1e-6f);
  EXPECT_NEAR(farPt.z / farPt.w, 1.0f, 1e-5f);
}

// glFrustum by hand for l = −1, r = 3, b = −2, t = 1, n = 2, f = 10: x' = (2n·x + (r+l)·z)/(r−l)
// = (4x + 2z)/4, y' = (4y − z)/3, w = −z. The window's corners on the near plane land on ±1, and a
// point halfway through depth keeps the symmetric projection's depth.
TEST(Mat4, FrustumMatchesTheHandComputationForAnAsymmetricWindow) {
  const Mat4 p = Mat4::frustum(-1, 3, -2, 1, 2, 10);
  const Vec4 q = p * Vec4{0.5f, -0.25f, -4, 1};
  EXPECT_FLOAT_EQ(q.x, (4 * 0.5f + 2 * -4.0f) / 4);
  EXPECT_FLOAT_EQ(q.y, (4 * -0.25f - -4.0f) / 3);
  EXPECT_FLOAT_EQ(q.w, 4);
  const Vec4 lowLeft = p * Vec4{-1, -2, -2, 1}, upRight = p * Vec4{3, 1, -2, 1};
  EXPECT_FLOAT_EQ(lowLeft.x / lowLeft.w, -1);
  EXPECT_FLOAT_EQ(lowLeft.y / lowLeft.w, -1);
  EXPECT_FLOAT_EQ(lowLeft.z / lowLeft.w, -1);
  EXPECT_FLOAT_EQ(upRight.x / upRight.w, 1);
  EXPECT_FLOAT_EQ(upRight.y / upRight.w, 1);
  // Symmetric, it is the perspective projection with the same depth row.
  const float t = std::tan(0.5f);
  const Mat4 s = Mat4::frustum(-2 * t * 1.5f, 2 * t * 1.5f, -2 * t, 2 * t, 2, 10);
  const Mat4 g = Mat4::perspective(1.0f, 1.5f, 2, 10);
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) EXPECT_NEAR(s.m[c][r], g.m[c][r], 1e-6f) << c << ", " << r;
  EXPECT_EQ(s.m[2][2], g.m[2][2]);
  EXPECT_EQ(s.m[3][2], g.m[3][2]);
}

TEST(Mat4, LookAtPutsTheTargetOnTheNegativeZAxis) {
  const Mat4 v = Mat4::lookAt({3, 4, 5}, {-1, 2, 0}, {0, 1, 0});
  const Vec3 t = v.transformPoint({-1, 2, 0});
  EXPECT_NEAR(t.x, 0, 1e-5f);
  EXPECT_NEAR(t.y, 0, 1e-5f);
  EXPECT_NEAR(t.z, -std::sqrt(16.0f + 4 + 25), 1e-4f);
}

// A failed check names the place, the condition and both operands, and stops the program; a check
// that holds does nothing.
TEST(Check, AFailedCheckPrintsTheConditionAndBothOperandsAndAborts) {
  SV_CHECK_EQ(2 + 2, 4);
  SV_CHECK(true);
  const int samples = 3;
  EXPECT_DEATH(SV_CHECK_LE(samples, 2),
               "core_test.cpp:[0-9]+: check failed: samples <= 2 \\(3 vs 2\\)");
  EXPECT_DEATH(SV_CHECK(samples == 4), "check failed: samples == 4");
}

// The pool is not reentrant: a job that starts another is stopped at once instead of deadlocking.
TEST(Check, AParallelForInsideAParallelForIsRefused) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");  // the pool's threads exist
  core::ThreadPool pool(2);
  EXPECT_DEATH(pool.parallelFor(8, [&](size_t, int) { pool.parallelFor(8, [](size_t, int) {}); }),
               "check failed: job_ == nullptr");
}

// Summing the views of a frame (a display's cells) adds every field: a record whose every 8-byte
// field holds the bit pattern 1 (the integer 1, or the smallest double) added to zeros gives it
// back — a field that operator+= missed would stay zero.
TEST(FrameStats, SummingAddsEveryField) {
  static_assert(sizeof(FrameStats) % 8 == 0);
  FrameStats one;
  std::vector<uint64_t> ones(sizeof(FrameStats) / 8, 1);
  std::memcpy(static_cast<void*>(&one), ones.data(), sizeof(FrameStats));
  FrameStats sum;
  sum += one;
  EXPECT_EQ(std::memcmp(static_cast<const void*>(&sum), static_cast<const void*>(&one),
                        sizeof(FrameStats)),
            0);
  sum += one;
  EXPECT_EQ(sum.trianglesIn, 2u);
  EXPECT_EQ(sum.volumeTerminated, 2u);
}

// The one path helper (synthvis/files.h), case by case.
TEST(Paths, AreTakenApartLexically) {
  EXPECT_EQ(core::directoryOf("scenes/ig/airport.json"), "scenes/ig");
  EXPECT_EQ(core::directoryOf("scene.json"), "");
  EXPECT_EQ(core::directoryOf("/scene.json"), "/");
  EXPECT_EQ(core::resolvePath("scenes/ig", "../airport.json"), "scenes/airport.json");
  EXPECT_EQ(core::resolvePath("scenes", "/abs/x.glb"), "/abs/x.glb");
  EXPECT_EQ(core::resolvePath("", "x.glb"), "x.glb");
  // Windows separators, as exporters on Windows write them: the file beside the referrer.
  EXPECT_EQ(core::resolvePath("models", ".\\textures\\wall.jpg"), "models/textures/wall.jpg");
  EXPECT_EQ(core::lowerExtension("a/B.GLB"), ".glb");
  EXPECT_EQ(core::lowerExtension("a.d/README"), "");
  EXPECT_EQ(core::fileName("maps/dem.tif"), "dem.tif");
  EXPECT_EQ(core::fileName("maps/"), "");
  EXPECT_EQ(core::withSuffix("out.png", "left"), "out-left.png");
  EXPECT_EQ(core::withSuffix("dir.v2/out", "0"), "dir.v2/out-0");
  EXPECT_EQ(core::withSuffix("a/b.tar.gz", "gl"), "a/b.tar-gl.gz");
}

// Reading is bounded and refuses what is not a regular file, naming the file and why.
TEST(ReadFile, RefusesDevicesDirectoriesAndFilesOverTheLimit) {
  const Result<std::string> device = core::readFile("/dev/zero");
  ASSERT_FALSE(device.ok());
  EXPECT_EQ(device.error().str(), "/dev/zero: cannot open file: not a regular file");
  EXPECT_FALSE(core::readFile("/").ok());
  const std::string path = tests::processTemp().write("six.txt", "123456");
  EXPECT_EQ(core::readFile(path).value(), "123456");
  const Result<std::string> big = core::readFile(path, 5);
  ASSERT_FALSE(big.ok());
  EXPECT_EQ(big.error().str(), path + ": file is too large (6 bytes, the limit is 5)");
}

TEST(WriteFile, WritesThePartsInOrder) {
  const std::string path = sv::tests::processTemp().path("parts.bin");
  const uint8_t bytes[] = {0, 1, 255};
  ASSERT_TRUE(core::writeFile(path, {"P6\n", "", core::bytesOf(bytes, sizeof bytes)}).ok());
  std::FILE* f = std::fopen(path.c_str(), "rb");
  ASSERT_NE(f, nullptr);
  char back[16] = {};
  const size_t n = std::fread(back, 1, sizeof back, f);
  std::fclose(f);
  EXPECT_EQ(std::string(back, n), std::string("P6\n\0\1\xff", 6));
}

TEST(WriteFile, AFileThatCannotBeMadeIsAnErrorNamingItAndTheReason) {
  const std::string path = sv::tests::processTemp().path("no-such-folder/out.glb");
  const Status s = core::writeFile(path, {"x"});
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().str(), path + ": cannot write: No such file or directory");
}

// A few bytes fit in the stream's buffer, so fwrite succeeds and only the flush meets the full
// disk: what a writer that checks only its writes reports as success.
TEST(WriteFile, ADiskThatFillsAtTheFlushIsAnError) {
  const std::string path = sv::tests::fullDiskPath("full.bin");
  if (path.empty()) GTEST_SKIP() << "no /dev/full here";
  const Status s = core::writeFile(path, {"a few bytes"});
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().str(), path + ": cannot write: No space left on device");
}

}  // namespace
}  // namespace sv
