// Test patterns: the same bytes every time, the structure their contract promises, and the
// docs' pictures (docs/images/pattern-*.png) kept equal to them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>

#include "present/test_patterns.h"

namespace sv::present {
namespace {

using Rgb = std::array<uint8_t, 3>;

Rgb at(const Image& im, int x, int y) {
  const uint8_t* p = im.pixel(x, y);
  return {p[0], p[1], p[2]};
}

constexpr Rgb kBlack{0, 0, 0}, kWhite{255, 255, 255}, kGrey{128, 128, 128}, kYellow{255, 255, 0};

TEST(PresentTestPattern, SameBytesEveryTime) {
  for (TestPattern p : {TestPattern::grid, TestPattern::colorBars, TestPattern::wedges}) {
    const Image a = testPattern(p, 333, 177, "left");
    const Image b = testPattern(p, 333, 177, "left");
    EXPECT_EQ(a.width, 333);
    EXPECT_EQ(a.height, 177);
    EXPECT_EQ(a.rgb.size(), size_t(333) * 177 * 3);
    EXPECT_EQ(a.rgb, b.rgb);
  }
  EXPECT_TRUE(testPattern(TestPattern::grid, 0, 10, "").rgb.empty());
}

TEST(PresentTestPattern, GridLinesAreAtMultiplesOf32) {
  const int w = 320, h = 200;
  const Image im = testPattern(TestPattern::grid, w, h, "");
  for (int y = 1; y < h - 1; ++y)
    for (int x = 1; x < w - 1; ++x) {
      const Rgb c = at(im, x, y);
      const bool onGrid = x % 32 == 0 || y % 32 == 0, onCross = x == w / 2 || y == h / 2;
      if (onCross) {
        EXPECT_EQ(c, kYellow) << x << "," << y;
      } else if (onGrid) {
        // Grey, or white where a circle crosses the line.
        EXPECT_TRUE(c == kGrey || c == kWhite) << x << "," << y;
      } else {
        EXPECT_TRUE(c == kBlack || c == kWhite) << x << "," << y;  // background or a circle
      }
    }
  // Grey runs the length of a grid line apart from circle crossings.
  int greys = 0;
  for (int y = 0; y < h; ++y) greys += at(im, 64, y) == kGrey;
  EXPECT_GT(greys, h - 20);
  // The white border, and the big circle touching the top and bottom (radius h/2 − 1).
  EXPECT_EQ(at(im, 0, 50), kWhite);
  EXPECT_EQ(at(im, w - 1, 50), kWhite);
  EXPECT_EQ(at(im, 77, h - 1), kWhite);
  EXPECT_EQ(at(im, w / 2 + 1, 1), kWhite);
}

TEST(PresentTestPattern, ColourBarsAreTheSeventyFivePercentSet) {
  const int w = 700, h = 480;
  const Image im = testPattern(TestPattern::colorBars, w, h, "left");
  const Rgb top[7] = {{191, 191, 191}, {191, 191, 0}, {0, 191, 191}, {0, 191, 0},
                      {191, 0, 191},   {191, 0, 0},   {0, 0, 191}};
  const Rgb middle[7] = {{0, 0, 191}, kBlack, {191, 0, 191}, kBlack, {0, 191, 191}, kBlack, {191, 191, 191}};
  for (int bar = 0; bar < 7; ++bar) {
    const int x = bar * w / 7 + w / 14;
    EXPECT_EQ(at(im, x, h / 3), top[bar]) << bar;
    EXPECT_EQ(at(im, x, h * 2 / 3 + 5), middle[bar]) << bar;
  }
  // The bottom row: −I, white, +Q in 15/84 blocks, the PLUGE's bright step.
  const int y = h - 3;
  EXPECT_EQ(at(im, w * 7 / 84, y), (Rgb{0, 33, 76}));
  EXPECT_EQ(at(im, w * 22 / 84, y), kWhite);
  EXPECT_EQ(at(im, w * 37 / 84, y), (Rgb{50, 0, 106}));
  EXPECT_EQ(at(im, w * 70 / 84, y), (Rgb{10, 10, 10}));
  EXPECT_EQ(at(im, w - 2, y), kBlack);
  // The label is white text somewhere in the bottom row's black block.
  int white = 0;
  for (int yy = h * 3 / 4; yy < h; ++yy)
    for (int x = w * 45 / 84; x < w * 60 / 84; ++x) white += at(im, x, yy) == kWhite;
  EXPECT_GT(white, 20);
}

TEST(PresentTestPattern, WedgesConvergeFromTheirSpreadToOnePixel) {
  const int w = 400, h = 300, side = 300;
  const Image im = testPattern(TestPattern::wedges, w, h, "centre");
  const int spread = side / 40, cx = w / 2, cy = h / 2, r = side / 6, gap = side / 30;
  // The top wedge's outer row: exactly its 11 lines, `spread` apart.
  const int outerY = h / 16;
  for (int x = cx - 6 * spread; x <= cx + 6 * spread; ++x) {
    const bool line = (x - cx) % spread == 0 && std::abs(x - cx) <= 5 * spread;
    EXPECT_EQ(at(im, x, outerY), line ? kWhite : kBlack) << x;
  }
  // Its inner row: 11 adjacent pixels, a solid run.
  for (int x = cx - 5; x <= cx + 5; ++x) EXPECT_EQ(at(im, x, cy - r - gap), kWhite) << x;
  EXPECT_EQ(at(im, cx - 6, cy - r - gap), kBlack);
  // The left wedge likewise, in y.
  const int outerX = w / 16;
  for (int y = cy - 6 * spread; y <= cy + 6 * spread; ++y) {
    const bool line = (y - cy) % spread == 0 && std::abs(y - cy) <= 5 * spread;
    EXPECT_EQ(at(im, outerX, y), line ? kWhite : kBlack) << y;
  }
  // The star's centre, the border, and the label changes the picture.
  EXPECT_EQ(at(im, cx, cy), kWhite);
  EXPECT_EQ(at(im, 0, 0), kWhite);
  EXPECT_NE(im.rgb, testPattern(TestPattern::wedges, w, h, "right").rgb);
}

TEST(PresentTestPattern, NamesParse) {
  EXPECT_EQ(parseTestPattern("grid").value(), TestPattern::grid);
  EXPECT_EQ(parseTestPattern("bars").value(), TestPattern::colorBars);
  EXPECT_EQ(parseTestPattern("wedges").value(), TestPattern::wedges);
  const auto bad = parseTestPattern("zebra");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().str(), "unknown test pattern 'zebra' (use grid, bars or wedges)");
}

// docs/presentation.md shows each pattern at 320×240 with the label "left"; the pictures there
// are these. SV_UPDATE_DOCS_IMAGES=1 rewrites them (then look at them before committing).
TEST(PresentTestPattern, DocsPicturesAreThePatterns) {
  const std::filesystem::path dir = std::filesystem::path(SV_SOURCE_DIR) / "docs" / "images";
  const bool update = std::getenv("SV_UPDATE_DOCS_IMAGES") != nullptr;
  const std::pair<TestPattern, const char*> patterns[] = {
      {TestPattern::grid, "grid"}, {TestPattern::colorBars, "bars"}, {TestPattern::wedges, "wedges"}};
  for (const auto& [pattern, name] : patterns) {
    const Image im = testPattern(pattern, 320, 240, "left");
    const std::string path = (dir / (std::string("pattern-") + name + ".png")).string();
    if (update) {
      ASSERT_TRUE(writePng(im, path).ok()) << path;
    }
    auto doc = readPng(path);
    ASSERT_TRUE(doc.ok()) << doc.error().str() << " (SV_UPDATE_DOCS_IMAGES=1 writes it)";
    EXPECT_EQ(doc->rgb, im.rgb) << path << " is stale: SV_UPDATE_DOCS_IMAGES=1 rewrites it";
  }
}

}  // namespace
}  // namespace sv::present
