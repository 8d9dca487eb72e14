// JPEG textures (texture/jpeg.h): what TurboJPEG encodes decodes to the same sRGB colours (within
// the codec's rounding), in linear light as PNG textures are; damaged and hostile files are
// refused with one line naming them.
#include "texture/jpeg.h"

#include <gtest/gtest.h>
#include <turbojpeg.h>

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "texture/texture.h"

namespace sv::texture {
namespace {

// A width × height RGB gradient, JPEG-encoded at quality 100 without chroma subsampling.
std::string encodeGradient(int width, int height, std::vector<uint8_t>& rgb) {
  rgb.resize(size_t(width) * height * 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      uint8_t* p = &rgb[(size_t(y) * width + x) * 3];
      p[0] = uint8_t(x * 255 / (width - 1));
      p[1] = uint8_t(y * 255 / (height - 1));
      p[2] = 128;
    }
  tjhandle tj = tjInitCompress();
  unsigned char* jpeg = nullptr;
  unsigned long size = 0;
  EXPECT_EQ(tjCompress2(tj, rgb.data(), width, 0, height, TJPF_RGB, &jpeg, &size, TJSAMP_444, 100,
                        TJFLAG_ACCURATEDCT),
            0);
  std::string bytes(reinterpret_cast<char*>(jpeg), size);
  tjFree(jpeg);
  tjDestroy(tj);
  return bytes;
}

TEST(Jpeg, DecodesToTheEncodedColoursInLinearLight) {
  std::vector<uint8_t> rgb;
  const std::string bytes = encodeGradient(64, 32, rgb);
  Result<Level> level = decodeTextureImage(bytes.data(), bytes.size(), "gradient.jpg");
  ASSERT_TRUE(level.ok()) << level.error().str();
  ASSERT_EQ(level->width, 64);
  ASSERT_EQ(level->height, 32);
  auto srgb = [](uint16_t linear) {
    const double l = linear / 65535.0;
    return 255 * (l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1 / 2.4) - 0.055);
  };
  double worst = 0;
  for (size_t i = 0; i < level->texels.size(); ++i) {
    const Texel& t = level->texels[i];
    EXPECT_EQ(t.a, 65535);
    worst = std::max({worst, std::fabs(srgb(t.r) - rgb[3 * i]), std::fabs(srgb(t.g) - rgb[3 * i + 1]),
                      std::fabs(srgb(t.b) - rgb[3 * i + 2])});
  }
  EXPECT_LE(worst, 5.0);  // quality 100, 4:4:4: the codec's own rounding
}

TEST(Jpeg, RefusesDamagedAndHostileFiles) {
  std::vector<uint8_t> rgb;
  const std::string bytes = encodeGradient(64, 32, rgb);
  auto error = [](const std::string& b) {
    Result<Level> r = decodeTextureImage(b.data(), b.size(), "x.jpg");
    EXPECT_FALSE(r.ok());
    return r.ok() ? std::string() : r.error().str();
  };
  EXPECT_NE(error(bytes.substr(0, 40)).find("x.jpg: invalid JPEG"), std::string::npos)
      << error(bytes.substr(0, 40));
  // A header claiming 60 000 × 60 000 pixels.
  std::string huge = bytes;
  for (size_t i = 0; i + 8 < huge.size(); ++i)
    if (uint8_t(huge[i]) == 0xFF && uint8_t(huge[i + 1]) == 0xC0) {  // SOF0: height, width
      huge[i + 5] = char(0xEA), huge[i + 6] = char(0x60);
      huge[i + 7] = char(0xEA), huge[i + 8] = char(0x60);
      break;
    }
  EXPECT_NE(error(huge).find("exceeds the limits"), std::string::npos) << error(huge);
  EXPECT_FALSE(decodeJpeg("\xFF\xD8", 2, "y.jpg", 100, 100).ok());
  EXPECT_FALSE(looksLikeJpeg("\x89PNG", 4));
}

}  // namespace
}  // namespace sv::texture
