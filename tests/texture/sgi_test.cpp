// SGI images (texture/sgi.h), OpenFlight's texture format: verbatim and run-length encoded files
// of 1 to 4 channels and 1 or 2 bytes a channel decode to the same pixels, rows top first; damaged
// and hostile files are refused with one line naming them.
#include "texture/sgi.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "texture/texture.h"

namespace sv::texture {
namespace {

void put(std::string& s, size_t at, uint32_t v, int n) {
  for (int i = 0; i < n; ++i) s[at + size_t(i)] = char(v >> (8 * (n - 1 - i)));
}

// planes[c][row][x] (rows bottom first, as the file stores them) as an SGI file.
std::string encode(const std::vector<std::vector<std::vector<uint8_t>>>& planes, bool rle,
                   int bpc) {
  const int channels = int(planes.size()), height = int(planes[0].size()),
            width = int(planes[0][0].size());
  std::string s(512, '\0');
  put(s, 0, 474, 2);
  s[2] = char(rle), s[3] = char(bpc);
  put(s, 4, 3, 2), put(s, 6, uint32_t(width), 2), put(s, 8, uint32_t(height), 2);
  put(s, 10, uint32_t(channels), 2);
  // A sample (16-bit: the value in the high byte, noise below) and a run's count (plain).
  auto unit = [&](std::string& out, uint32_t v) {
    out.append(size_t(bpc), '\0');
    put(out, out.size() - size_t(bpc), bpc == 1 ? v : v << 8 | 0x5A, bpc);
  };
  auto count = [&](std::string& out, uint32_t n) {
    out.append(size_t(bpc), '\0');
    put(out, out.size() - size_t(bpc), n, bpc);
  };
  if (!rle) {
    for (const auto& plane : planes)
      for (const auto& row : plane)
        for (uint8_t v : row) unit(s, v);
    return s;
  }
  const size_t rows = size_t(channels) * size_t(height);
  s.append(8 * rows, '\0');
  for (size_t c = 0; c < planes.size(); ++c)
    for (size_t r = 0; r < planes[c].size(); ++r) {
      const std::vector<uint8_t>& row = planes[c][r];
      const size_t start = s.size();
      // A repeat run of the first value over its equal neighbours, then the rest literally.
      size_t x = 0;
      while (x < row.size() && row[x] == row[0] && x < 127) ++x;
      count(s, uint32_t(x)), unit(s, row[0]);
      for (size_t k = x; k < row.size(); k += 127) {
        const size_t n = std::min<size_t>(127, row.size() - k);
        count(s, uint32_t(0x80 | n));
        for (size_t i = 0; i < n; ++i) unit(s, row[k + i]);
      }
      count(s, 0);
      const size_t index = c * size_t(height) + r;
      put(s, 512 + 4 * index, uint32_t(start), 4);
      put(s, 512 + 4 * rows + 4 * index, uint32_t(s.size() - start), 4);
    }
  return s;
}

std::vector<std::vector<std::vector<uint8_t>>> sample(int channels, int width, int height) {
  std::vector<std::vector<std::vector<uint8_t>>> planes(static_cast<size_t>(channels));
  for (int c = 0; c < channels; ++c)
    for (int y = 0; y < height; ++y) {
      std::vector<uint8_t> row(size_t(width), uint8_t(40 * c));
      for (int x = width / 2; x < width; ++x) row[size_t(x)] = uint8_t(x * 7 + y * 13 + c * 50);
      planes[size_t(c)].push_back(row);
    }
  return planes;
}

TEST(Sgi, VerbatimAndRunLengthFilesDecodeToTheSamePixels) {
  for (int channels : {1, 2, 3, 4})
    for (int bpc : {1, 2}) {
      SCOPED_TRACE(testing::Message() << channels << " channels, " << bpc << " bytes");
      const auto planes = sample(channels, 300, 5);  // rows longer than one run
      auto verbatim = decodeSgi(encode(planes, false, bpc).data(), encode(planes, false, bpc).size(),
                                "v.rgb", 16384, 1 << 26);
      const std::string packed = encode(planes, true, bpc);
      auto rle = decodeSgi(packed.data(), packed.size(), "r.rgb", 16384, 1 << 26);
      ASSERT_TRUE(verbatim.ok()) << verbatim.error().str();
      ASSERT_TRUE(rle.ok()) << rle.error().str();
      EXPECT_EQ(verbatim->rgba, rle->rgba);
      ASSERT_EQ(verbatim->width, 300);
      ASSERT_EQ(verbatim->height, 5);
      // Pixel (200, 0) of the image is the file's top row, 4 (rows run bottom first).
      const uint8_t* p = &verbatim->rgba[(0 * 300 + 200) * 4];
      const uint8_t first = uint8_t(200 * 7 + 4 * 13);
      EXPECT_EQ(p[0], first);
      EXPECT_EQ(p[1], channels >= 3 ? uint8_t(first + 50) : first);
      EXPECT_EQ(p[3], channels == 2 ? uint8_t(first + 50) : channels == 4 ? uint8_t(first + 150) : 255);
    }
}

TEST(Sgi, IsATextureImage) {
  const std::string file = encode(sample(3, 8, 4), true, 1);
  auto level = decodeTextureImage(file.data(), file.size(), "t.rgb");
  ASSERT_TRUE(level.ok()) << level.error().str();
  EXPECT_EQ(level->width, 8);
  EXPECT_EQ(level->height, 4);
  EXPECT_EQ(level->at(0, 0).a, 65535);
}

TEST(Sgi, RefusesDamagedFiles) {
  auto error = [](std::string bytes) {
    auto r = decodeSgi(bytes.data(), bytes.size(), "bad.rgb", 4096, 1 << 20);
    return r.ok() ? std::string("(decoded)") : r.error().str();
  };
  const std::string good = encode(sample(3, 20, 6), true, 1);
  EXPECT_EQ(error(good), "(decoded)");
  EXPECT_EQ(error(good.substr(0, 300)), "bad.rgb: SGI image: shorter than its header");
  std::string big = good;
  put(big, 6, 5000, 2);
  EXPECT_EQ(error(big), "bad.rgb: SGI image: size 5000×6 (1 to 4096 a side, 1048576 pixels)");
  std::string outside = good;
  put(outside, 512, 1u << 30, 4);
  EXPECT_EQ(error(outside), "bad.rgb: SGI image: run 0 lies outside the file");
  std::string overflow = good;
  overflow[size_t(uint8_t(good[512]) << 24 | uint8_t(good[513]) << 16 | uint8_t(good[514]) << 8 |
                  uint8_t(good[515]))] = char(127);  // a first run longer than the row
  EXPECT_EQ(error(overflow), "bad.rgb: SGI image: run 0 overflows its row");
  EXPECT_EQ(error(encode(sample(3, 20, 6), false, 1).substr(0, 600)), "bad.rgb: SGI image: truncated");
  std::string map = good;
  put(map, 104, 1, 4);
  EXPECT_EQ(error(map), "bad.rgb: SGI image: colour-mapped images are not supported");
}

}  // namespace
}  // namespace sv::texture
