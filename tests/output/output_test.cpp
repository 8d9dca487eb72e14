#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

#include "output/resolve.h"
#include "raster/framebuffer.h"
#include "support/temp_dir.h"
#include "synthvis/image.h"

namespace sv {
namespace {

std::string tempPath(const char* name) { return sv::tests::processTemp().path(name); }

Image gradient(int w, int h) {
  Image img{w, h, std::vector<uint8_t>(size_t(w) * h * 3)};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = img.pixel(x, y);
      p[0] = uint8_t(x * 7);
      p[1] = uint8_t(y * 13);
      p[2] = uint8_t(x ^ y);
    }
  return img;
}

TEST(ImageIo, PngRoundTripIsLossless) {
  const Image img = gradient(37, 19);
  const std::string path = tempPath("sv_roundtrip.png");
  ASSERT_TRUE(writePng(img, path).ok());
  auto back = readPng(path);
  ASSERT_TRUE(back.ok()) << back.error().str();
  EXPECT_EQ(back->width, 37);
  EXPECT_EQ(back->height, 19);
  EXPECT_EQ(back->rgb, img.rgb);
}

// SPEC §9: channels side by side, in order; the shorter one padded below with black.
TEST(Mosaic, PutsChannelsSideBySideAndPadsShorterOnesWithBlack) {
  const Image a = gradient(5, 4), b = gradient(3, 7);
  const Image m = mosaic({a, b});
  ASSERT_EQ(m.width, 8);
  ASSERT_EQ(m.height, 7);
  for (int y = 0; y < 7; ++y)
    for (int x = 0; x < 8; ++x)
      for (int c = 0; c < 3; ++c) {
        const int expected = x < 5 ? (y < 4 ? a.pixel(x, y)[c] : 0) : b.pixel(x - 5, y)[c];
        ASSERT_EQ(m.pixel(x, y)[c], expected) << x << ", " << y;
      }
  EXPECT_EQ(mosaic({}).rgb.size(), 0u);
}

TEST(ImageIo, PpmHasBinaryP6HeaderAndPixels) {
  const Image img = gradient(5, 3);
  const std::string path = tempPath("sv_img.ppm");
  ASSERT_TRUE(writeImage(img, path).ok());
  std::ifstream f(path, std::ios::binary);
  std::string data((std::istreambuf_iterator<char>(f)), {});
  const std::string header = "P6\n5 3\n255\n";
  ASSERT_EQ(data.substr(0, header.size()), header);
  EXPECT_EQ(data.size(), header.size() + 45);
  EXPECT_EQ(uint8_t(data[header.size() + 3]), img.rgb[3]);
}

TEST(ImageIo, ErrorsNameTheFile) {
  auto missing = readPng("/nonexistent/dir/x.png");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().str().find("/nonexistent/dir/x.png"), std::string::npos);
  const std::string bad = tempPath("sv_not_a_png.png");
  std::ofstream(bad) << "this is not a png";
  auto garbage = readPng(bad);
  ASSERT_FALSE(garbage.ok());
  EXPECT_NE(garbage.error().str().find(bad), std::string::npos);
  EXPECT_FALSE(writeImage(gradient(2, 2), tempPath("sv_img.bmp")).ok());
}

// Both formats on a full disk: the PPM writer checked only its fwrites, which a small image's
// bytes pass (they wait in the buffer), and reported success.
TEST(ImageIo, AFullDiskIsAnError) {
  for (const char* name : {"full.ppm", "full.png"}) {
    const std::string path = sv::tests::fullDiskPath(name);
    if (path.empty()) GTEST_SKIP() << "no /dev/full here";
    const Status s = writeImage(gradient(2, 2), path);
    ASSERT_FALSE(s.ok()) << name;
    EXPECT_NE(s.error().str().find(path + ": cannot write"), std::string::npos) << s.error().str();
    EXPECT_NE(s.error().str().find("No space left on device"), std::string::npos)
        << s.error().str();
  }
}

// The image reader is the texture maps' (texture/png.h): the same size limit and the same refusal
// of a header that claims more than the file can hold, before anything is allocated.
TEST(ImageIo, ReadsThroughTheOnePngCodecWithItsLimits) {
  std::vector<uint8_t> black(size_t(4096) * 4096 * 3, 0);
  Image big{4096, 4096, black};
  const std::string path = tempPath("sv_big.png");
  ASSERT_TRUE(writePng(big, path).ok());
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), {});
  bytes.resize(300);  // a few hundred bytes cannot hold 16 M pixels
  auto shortFile = decodePng(bytes.data(), bytes.size(), "short.png");
  ASSERT_FALSE(shortFile.ok());
  EXPECT_NE(shortFile.error().str().find("short.png: 300 bytes of PNG cannot hold"),
            std::string::npos)
      << shortFile.error().str();
  std::vector<uint8_t> row(size_t(8193) * 3, 0);
  const std::string wide = tempPath("sv_wide.png");
  ASSERT_TRUE(writePng(Image{8193, 1, row}, wide).ok());
  // A pipe's size cannot be known, which bounds nothing: its image reads.
  const std::string fifo = tempPath("sv_fifo.png");
  std::remove(fifo.c_str());
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const Image picture = gradient(300, 200);
  const std::string picturePath = tempPath("sv_picture.png");
  ASSERT_TRUE(writePng(picture, picturePath).ok());
  std::thread writer([&] {
    std::ifstream from(picturePath, std::ios::binary);
    std::ofstream to(fifo, std::ios::binary);
    to << from.rdbuf();
  });
  auto piped = readPng(fifo);
  writer.join();
  ASSERT_TRUE(piped.ok()) << piped.error().str();
  EXPECT_EQ(piped->rgb, picture.rgb);
  auto tooWide = readPng(wide);
  ASSERT_FALSE(tooWide.ok());
  EXPECT_NE(tooWide.error().str().find("PNG size 8193x1 is out of range"), std::string::npos)
      << tooWide.error().str();
}

TEST(Gamma, DisplayGammaTable) {
  const auto g = output::GammaTable::power(2.2);
  EXPECT_EQ(g.table[0], 0);
  EXPECT_EQ(g.table[65535], 255);
  EXPECT_EQ(g.table[32768], 186);  // 0.5^(1/2.2) = 0.7297 → 186.1
  const auto linear = output::GammaTable::power(1.0);
  EXPECT_EQ(linear.table[32768], 128);  // 0.50001 → 127.5 → 128
  for (int i = 1; i < 65536; ++i) ASSERT_GE(g.table[i], g.table[i - 1]);
}

TEST(Gamma, SrgbTablesMatchTheStandardAtKnownPoints) {
  const auto g = output::GammaTable::srgb();
  EXPECT_EQ(g.table[0], 0);
  EXPECT_EQ(g.table[65535], 255);
  EXPECT_EQ(g.table[32768], 188);                // linear 0.5 → sRGB 0.7354 → 187.5 → 188
  EXPECT_EQ(g.table[int(0.2140 * 65535)], 127);  // linear 0.2140 → sRGB 0.49996 → 127.49
  EXPECT_EQ(g.table[int(0.2159 * 65535)], 128);  // sRGB 128/255 is linear 0.21586
  for (int i = 1; i < 65536; ++i) ASSERT_GE(g.table[i], g.table[i - 1]);  // monotonic
}

// Every pixel of full and partial tiles, of one colour or many, in images whose rows start at
// every alignment (the resolve streams rows where the image allows and copies the rest).
TEST(Resolve, TilePixelsAreTheirColoursThroughTheTable) {
  const auto g = output::GammaTable::srgb();
  for (const int width : {64, 70, 133, 200}) {
    const int height = 131;
    Image image;
    output::prepareImage(width, height, image);
    std::fill(image.rgb.begin(), image.rgb.end(), uint8_t(0xAB));
    const int tilesX = (width + raster::kTileSize - 1) / raster::kTileSize;
    const int tilesY = (height + raster::kTileSize - 1) / raster::kTileSize;
    std::vector<uint16_t> color(size_t(raster::kTilePixels) * 3);
    // Tiles of one colour, of one colour but their last pixel, and of many colours.
    auto value = [&](int x, int y, int ch) {
      const int tx = x / raster::kTileSize, ty = y / raster::kTileSize;
      const int lx = x % raster::kTileSize, ly = y % raster::kTileSize;
      switch ((tx + ty) % 3) {
        case 0:
          return uint16_t(1234 + ch * 20000);
        case 1:
          return uint16_t(lx == 63 && ly == 63 ? 60000 : 1234 + ch * 20000);
        default:
          return uint16_t((x * 977 + y * 131 + ch * 7919) * 13);
      }
    };
    for (int ty = 0; ty < tilesY; ++ty)
      for (int tx = 0; tx < tilesX; ++tx) {
        for (int ly = 0; ly < raster::kTileSize; ++ly)
          for (int lx = 0; lx < raster::kTileSize; ++lx)
            for (int ch = 0; ch < 3; ++ch)
              color[raster::FrameBuffer::colorOffset(lx, ly, ch)] =
                  value(tx * raster::kTileSize + lx, ty * raster::kTileSize + ly, ch);
        output::resolveTile(color.data(), tx, ty, g, image);
      }
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        for (int ch = 0; ch < 3; ++ch)
          ASSERT_EQ(image.pixel(x, y)[ch], g.table[value(x, y, ch)])
              << "width " << width << " pixel " << x << "," << y << " channel " << ch;
  }
}

}  // namespace
}  // namespace sv
