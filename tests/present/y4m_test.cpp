// The y4m stream: BT.601 values of known colours, the header, and a written stream parsed back.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "present/present.h"
#include "present/y4m.h"
#include "support/temp_dir.h"

namespace sv::present {
namespace {

// BT.601 limited range in floating point, straight from the standard's equations: the independent
// evaluation the fixed-point conversion is checked against.
void referenceYuv(int r, int g, int b, double out[3]) {
  const double kr = 0.299, kb = 0.114, kg = 1 - kr - kb;
  const double ey = (kr * r + kg * g + kb * b) / 255.0;
  out[0] = 16 + 219 * ey;
  out[1] = 128 + 224 * (b / 255.0 - ey) / (2 * (1 - kb));
  out[2] = 128 + 224 * (r / 255.0 - ey) / (2 * (1 - kr));
}

TEST(PresentY4m, KnownColoursGiveTheStudioRangeValues) {
  // The classic BT.601 8-bit table: 100 % primaries and secondaries.
  struct Case {
    uint8_t r, g, b, y, u, v;
  } cases[] = {
      {255, 255, 255, 235, 128, 128}, {0, 0, 0, 16, 128, 128},     {255, 0, 0, 81, 90, 240},
      {0, 255, 0, 145, 54, 34},       {0, 0, 255, 41, 240, 110},   {255, 255, 0, 210, 16, 146},
      {0, 255, 255, 170, 166, 16},    {255, 0, 255, 106, 202, 222},
  };
  for (const Case& c : cases) {
    const Yuv yuv = rgbToYuv601(c.r, c.g, c.b);
    EXPECT_EQ(yuv.y, c.y) << int(c.r) << "," << int(c.g) << "," << int(c.b);
    EXPECT_EQ(yuv.u, c.u) << int(c.r) << "," << int(c.g) << "," << int(c.b);
    EXPECT_EQ(yuv.v, c.v) << int(c.r) << "," << int(c.g) << "," << int(c.b);
  }
}

TEST(PresentY4m, EveryGreyHasNoColour) {
  for (int k = 0; k < 256; ++k) {
    const Yuv yuv = rgbToYuv601(uint8_t(k), uint8_t(k), uint8_t(k));
    EXPECT_EQ(yuv.u, 128) << k;
    EXPECT_EQ(yuv.v, 128) << k;
  }
}

TEST(PresentY4m, FixedPointMatchesTheFloatingPointEquationsToHalfALevel) {
  // A 17³ lattice of the RGB cube, ends included.
  for (int r = 0; r <= 255; r += 15)
    for (int g = 0; g <= 255; g += 15)
      for (int b = 0; b <= 255; b += 15) {
        double ref[3];
        referenceYuv(r, g, b, ref);
        const Yuv yuv = rgbToYuv601(uint8_t(r), uint8_t(g), uint8_t(b));
        const int got[3] = {yuv.y, yuv.u, yuv.v};
        for (int k = 0; k < 3; ++k) EXPECT_LE(std::abs(got[k] - ref[k]), 0.5 + 1e-3) << r << "," << g << "," << b;
      }
}

TEST(PresentY4m, HeaderNamesSizeRateAndColourSpace) {
  EXPECT_EQ(y4mHeader(640, 480, 60), "YUV4MPEG2 W640 H480 F60:1 Ip A1:1 C444 XCOLORRANGE=LIMITED\n");
}

// A y4m stream read back: the header's tokens and each frame's planes.
struct Y4m {
  int width = 0, height = 0;
  std::string rate, colour;
  std::vector<std::string> frames;  // Y, U, V planes, 3·W·H bytes each
};

Y4m parseY4m(const std::string& bytes) {
  Y4m out;
  const size_t eol = bytes.find('\n');
  std::istringstream header(bytes.substr(0, eol));
  std::string token;
  header >> token;
  EXPECT_EQ(token, "YUV4MPEG2");
  while (header >> token) {
    if (token[0] == 'W') out.width = std::stoi(token.substr(1));
    if (token[0] == 'H') out.height = std::stoi(token.substr(1));
    if (token[0] == 'F') out.rate = token.substr(1);
    if (token[0] == 'C') out.colour = token.substr(1);
  }
  const size_t planes = size_t(out.width) * out.height * 3;
  for (size_t at = eol + 1; at < bytes.size();) {
    EXPECT_EQ(bytes.substr(at, 6), "FRAME\n");
    at += 6;
    EXPECT_LE(at + planes, bytes.size());
    out.frames.push_back(bytes.substr(at, planes));
    at += planes;
  }
  return out;
}

Image solid(int w, int h, uint8_t r, uint8_t g, uint8_t b) {
  Image im{w, h, std::vector<uint8_t>(size_t(w) * h * 3)};
  for (size_t i = 0; i < im.rgb.size(); i += 3) im.rgb[i] = r, im.rgb[i + 1] = g, im.rgb[i + 2] = b;
  return im;
}

std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(PresentY4m, StreamOfTwoChannelsIsTheirMosaicFrameByFrame) {
  const auto path = sv::tests::processTemp().dir() / "stream.y4m";
  {
    auto presenter = makePresenter("y4m:" + path.string(), 30);
    ASSERT_TRUE(presenter.ok()) << presenter.error().str();
    // Two channels: 3×2 red beside 2×2 blue, then both white.
    const std::string names[2] = {"left", "right"};
    const Image first[2] = {solid(3, 2, 255, 0, 0), solid(2, 2, 0, 0, 255)};
    const Image second[2] = {solid(3, 2, 255, 255, 255), solid(2, 2, 255, 255, 255)};
    ASSERT_TRUE(presenter.value()->present({1, first, names}).ok());
    ASSERT_TRUE(presenter.value()->flush().ok());  // the queue is 3 deep: flush so none is dropped
    ASSERT_TRUE(presenter.value()->present({2, second, names}).ok());
    ASSERT_TRUE(presenter.value()->flush().ok());
    EXPECT_EQ(presenter.value()->dropped(), 0u);
  }
  const Y4m y4m = parseY4m(readFile(path));
  EXPECT_EQ(y4m.width, 5);
  EXPECT_EQ(y4m.height, 2);
  EXPECT_EQ(y4m.rate, "30:1");
  EXPECT_EQ(y4m.colour, "444");
  ASSERT_EQ(y4m.frames.size(), 2u);
  const size_t n = 10;
  const std::string& f = y4m.frames[0];
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 5; ++x) {
      const size_t i = size_t(y) * 5 + x;
      const bool red = x < 3;
      EXPECT_EQ(uint8_t(f[i]), red ? 81 : 41);
      EXPECT_EQ(uint8_t(f[n + i]), red ? 90 : 240);
      EXPECT_EQ(uint8_t(f[2 * n + i]), red ? 240 : 110);
    }
  EXPECT_EQ(y4m.frames[1], std::string(n, char(235)) + std::string(2 * n, char(128)));
  std::filesystem::remove(path);
}

// Each frame is flushed (a player at the end of a pipe shows it now), so a full disk fails the
// frame it cut short.
TEST(PresentY4m, AFullDiskIsAnError) {
  const std::string path = sv::tests::fullDiskPath("full.y4m");
  if (path.empty()) GTEST_SKIP() << "no /dev/full here";
  std::FILE* f = std::fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  Y4mWriter writer(f, path, 25);
  const Status s = writer.write(solid(4, 4, 1, 2, 3));
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().str(), path + ": y4m: write failed: No space left on device");
  EXPECT_FALSE(writer.brokenPipe());
  std::fclose(f);
}

TEST(PresentY4m, FrameOfAnotherSizeIsAnError) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  Y4mWriter writer(f, "out.y4m", 25);
  EXPECT_TRUE(writer.write(solid(4, 4, 1, 2, 3)).ok());
  const Status s = writer.write(solid(4, 5, 1, 2, 3));
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().str(), "out.y4m: y4m: frame size changed from 4x4 to 4x5");
  std::fclose(f);
}

}  // namespace
}  // namespace sv::present
