// Based on: seed 004's built-in test (projector alignment); SMPTE EG 1-1990 for the colour bars'
// layout (75 % bars, reversed blue row, −I / white / +Q / PLUGE), here in full-range 8-bit RGB
// rather than a composite signal, hence "SMPTE-like": the PLUGE's −4 % step clips to black.
#include "present/test_patterns.h"

#include <algorithm>
#include <cmath>

#include "present/draw.h"
#include "present/overlay.h"

namespace sv::present {
namespace {

using detail::Rgb;

constexpr Rgb kBlack{0, 0, 0}, kWhite{255, 255, 255}, kGridGrey{128, 128, 128},
    kCrossYellow{255, 255, 0};
constexpr int kGridStep = 32;

void drawBorder(Image& image, Rgb c) {
  const int w = image.width, h = image.height;
  detail::fillRect(image, 0, 0, w, 1, c);
  detail::fillRect(image, 0, h - 1, w, h, c);
  detail::fillRect(image, 0, 0, 1, h, c);
  detail::fillRect(image, w - 1, 0, w, h, c);
}

// The label's scale: about 1/160 of the smaller side, so that it reads at projector sizes.
int labelScale(const Image& image) { return std::max(1, std::min(image.width, image.height) / 160); }

Image gridPattern(int w, int h) {
  Image image = detail::filledImage(w, h, kBlack);
  for (int x = 0; x < w; x += kGridStep) detail::fillRect(image, x, 0, x + 1, h, kGridGrey);
  for (int y = 0; y < h; y += kGridStep) detail::fillRect(image, 0, y, w, y + 1, kGridGrey);
  // Circles show a projector's aspect and its distortion across the field: one as large as the
  // image allows, eight small ones at the sixths.
  const int cx = w / 2, cy = h / 2, side = std::min(w, h);
  detail::drawCircle(image, cx, cy, side / 2 - 1, kWhite);
  for (int j = 1; j <= 5; j += 2)
    for (int i = 1; i <= 5; i += 2)
      if (i != 3 || j != 3) detail::drawCircle(image, w * i / 6, h * j / 6, side / 10, kWhite);
  detail::fillRect(image, cx, 0, cx + 1, h, kCrossYellow);
  detail::fillRect(image, 0, cy, w, cy + 1, kCrossYellow);
  drawBorder(image, kWhite);
  return image;
}

Image colorBarsPattern(int w, int h, const std::string& label) {
  // 75 % of 255, rounded down as 8-bit bar generators do.
  constexpr uint8_t k75 = 191;
  constexpr Rgb kTop[7] = {{k75, k75, k75}, {k75, k75, 0}, {0, k75, k75}, {0, k75, 0},
                           {k75, 0, k75},   {k75, 0, 0},   {0, 0, k75}};
  constexpr Rgb kMiddle[7] = {{0, 0, k75},   kBlack, {k75, 0, k75}, kBlack,
                              {0, k75, k75}, kBlack, {k75, k75, k75}};
  // −I and +Q as RGB (the I and Q axes at 20 % amplitude), the PLUGE steps at −4 %, 0, +4 %.
  constexpr Rgb kMinusI{0, 33, 76}, kPlusQ{50, 0, 106}, kPluge[3] = {kBlack, kBlack, {10, 10, 10}};
  Image image = detail::filledImage(w, h, kBlack);
  const int yMiddle = h * 2 / 3, yBottom = h * 3 / 4;
  for (int x = 0; x < w; ++x) {
    const int bar = x * 7 / w;
    detail::fillRect(image, x, 0, x + 1, yMiddle, kTop[bar]);
    detail::fillRect(image, x, yMiddle, x + 1, yBottom, kMiddle[bar]);
    // The bottom row in 84ths: four 15/84 blocks (−I, white, +Q, black), the PLUGE's three
    // 4/84 steps, black under the last bar.
    const int u = x * 84 / w;
    Rgb c = kBlack;
    if (u < 15) c = kMinusI;
    else if (u < 30) c = kWhite;
    else if (u < 45) c = kPlusQ;
    else if (u >= 60 && u < 72) c = kPluge[(u - 60) / 4];
    detail::fillRect(image, x, yBottom, x + 1, h, c);
  }
  // The label on a black box in the bottom row's black block, where it hides no bar.
  const int scale = labelScale(image);
  const TextSize size = measureText(label, scale);
  const int x0 = w * 45 / 84 + 2 * scale, y0 = yBottom + (h - yBottom - size.height) / 2;
  detail::fillRect(image, x0 - scale, y0 - scale, x0 + size.width + scale, y0 + size.height + scale,
                   kBlack);
  drawText(image, x0, y0, label, 255, 255, 255, scale);
  return image;
}

Image wedgesPattern(int w, int h, const std::string& label) {
  Image image = detail::filledImage(w, h, kBlack);
  const int cx = w / 2, cy = h / 2, side = std::min(w, h);
  // The star: 72 rays, 5° apart, from the centre out to R; its rays merge where their spacing
  // falls below a pixel, at radius 72 / 2π ≈ 11.5 px on a perfect display.
  const int r = side / 6;
  for (int k = 0; k < 72; ++k) {
    const double a = k * (2.0 * 3.14159265358979323846 / 72.0);
    detail::drawLine(image, cx, cy, cx + int(std::lround(r * std::cos(a))),
                     cy - int(std::lround(r * std::sin(a))), kWhite);
  }
  // Four wedges of 11 lines converging from `spread` px apart at the outer end to 1 px apart at
  // the inner end, which stops `gap` px short of the star.
  const int spread = std::max(4, side / 40), gap = std::max(4, side / 30);
  const int outerY = std::max(2, h / 16), outerX = std::max(2, w / 16);
  for (int k = -5; k <= 5; ++k) {
    detail::drawLine(image, cx + k * spread, outerY, cx + k, cy - r - gap, kWhite);
    detail::drawLine(image, cx + k * spread, h - 1 - outerY, cx + k, cy + r + gap, kWhite);
    detail::drawLine(image, outerX, cy + k * spread, cx - r - gap, cy + k, kWhite);
    detail::drawLine(image, w - 1 - outerX, cy + k * spread, cx + r + gap, cy + k, kWhite);
  }
  drawBorder(image, kWhite);
  const int scale = labelScale(image);
  drawText(image, 4 * scale, 4 * scale, label, 255, 255, 255, scale);
  return image;
}

}  // namespace

Image testPattern(TestPattern pattern, int width, int height, const std::string& label) {
  if (width < 1 || height < 1) return {};
  switch (pattern) {
    case TestPattern::grid: return gridPattern(width, height);
    case TestPattern::colorBars: return colorBarsPattern(width, height, label);
    case TestPattern::wedges: return wedgesPattern(width, height, label);
  }
  return {};
}

Result<TestPattern> parseTestPattern(std::string_view name) {
  if (name == "grid") return TestPattern::grid;
  if (name == "bars" || name == "colorBars" || name == "color-bars") return TestPattern::colorBars;
  if (name == "wedges") return TestPattern::wedges;
  return Error{"", "", "unknown test pattern '" + std::string(name) + "' (use grid, bars or wedges)"};
}

}  // namespace sv::present
