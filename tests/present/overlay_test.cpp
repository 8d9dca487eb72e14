// The 5×7 font and the overlay: glyph pixels exactly, nothing outside a glyph's box.
#include <gtest/gtest.h>

#include <set>
#include <vector>

#include "present/overlay.h"

namespace sv::present {
namespace {

Image filled(int w, int h, uint8_t v) { return Image{w, h, std::vector<uint8_t>(size_t(w) * h * 3, v)}; }

TEST(PresentFont, EveryPrintableGlyphIsFiveBitsWideAndDistinct) {
  std::set<std::vector<uint8_t>> seen;
  for (int c = 32; c <= 126; ++c) {
    const uint8_t* rows = glyphRows(char(c));
    std::vector<uint8_t> g(rows, rows + kGlyphHeight);
    int bits = 0;
    for (uint8_t row : g) {
      EXPECT_LT(row, 32) << char(c);
      bits += __builtin_popcount(row);
    }
    if (c != ' ') {
      EXPECT_GT(bits, 0) << char(c);
    }
    EXPECT_TRUE(seen.insert(g).second) << "glyph '" << char(c) << "' repeats another";
  }
  EXPECT_EQ(glyphRows('\x01'), glyphRows('?'));
  EXPECT_EQ(glyphRows('\xe9'), glyphRows('?'));
}

TEST(PresentDrawText, DrawsTheGlyphsPixelsAndNothingOutsideItsBox) {
  for (int scale : {1, 3}) {
    Image im = filled(40, 40, 0);
    const int x0 = 10, y0 = 12;
    drawText(im, x0, y0, "A", 255, 0, 0, scale);
    const uint8_t* rows = glyphRows('A');
    for (int y = 0; y < im.height; ++y)
      for (int x = 0; x < im.width; ++x) {
        const int col = (x - x0) / scale, row = (y - y0) / scale;
        const bool inside = x >= x0 && y >= y0 && col < kGlyphWidth && row < kGlyphHeight;
        const bool set = inside && (rows[row] & (0x10 >> col));
        const uint8_t* p = im.pixel(x, y);
        EXPECT_EQ(p[0], set ? 255 : 0) << x << "," << y << " scale " << scale;
        EXPECT_EQ(p[1], 0);
        EXPECT_EQ(p[2], 0);
      }
  }
}

TEST(PresentDrawText, ClipsAtTheImageEdges) {
  Image im = filled(8, 8, 7);
  drawText(im, -4, -4, "W", 1, 2, 3, 1);
  drawText(im, 5, 6, "M\nM", 1, 2, 3, 2);
  EXPECT_EQ(im.rgb.size(), size_t(8 * 8 * 3));
  EXPECT_EQ(im.pixel(0, 0)[0], 1);  // W's row 4, column 4 is set: 0x15 & 0x01
}

TEST(PresentDrawText, MeasureCoversLinesAndScale) {
  EXPECT_EQ(measureText("").width, 0);
  EXPECT_EQ(measureText("ab").width, 11);
  EXPECT_EQ(measureText("ab").height, 7);
  EXPECT_EQ(measureText("abc\nd", 2).width, 34);
  EXPECT_EQ(measureText("abc\nd", 2).height, 32);
}

TEST(PresentOverlay, DarkensATopLeftBoxAndWritesTheLines) {
  Image im = filled(200, 100, 200);
  const std::string lines[] = {"raster 3.1 ms", "level 2"};
  drawOverlay(im, lines);
  const int boxW = measureText(lines[0]).width + 8, boxH = 2 * kCellHeight - 2 + 8;
  int text = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      const uint8_t* p = im.pixel(x, y);
      if (x >= boxW || y >= boxH) {
        EXPECT_EQ(p[0], 200) << x << "," << y;  // untouched outside the box
      } else if (p[0] == 160 && p[1] == 255) {
        ++text;
      } else {
        EXPECT_EQ(p[0], (200 * 96 + 128) >> 8) << x << "," << y;  // 3/8 of what was there
      }
    }
  EXPECT_GT(text, 50);
}

}  // namespace
}  // namespace sv::present
