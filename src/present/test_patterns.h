// Test patterns for aligning projectors and checking a channel's sharpness (seed 004's built-in
// test): drawn, not loaded, at any size, the same bytes on every machine.
#pragma once

#include <string>
#include <string_view>

#include "synthvis/image.h"
#include "synthvis/result.h"

namespace sv::present {

enum class TestPattern {
  // Black, 1-px grey lines every 32 px (x and y multiples of 32), a 1-px yellow centre cross at
  // (width/2, height/2) the whole width and height, a white circle of radius min(w, h)/2 − 1 and
  // eight small ones around it, a 1-px white border.
  grid,
  // SMPTE-like 75 % bars: seven bars (grey, yellow, cyan, green, magenta, red, blue at 191) over
  // the top 2/3; a short row of reversed bars (blue, black, magenta, black, cyan, black, grey);
  // the bottom quarter −I, 100 % white, +Q, black and a PLUGE step (0, 0, 10), then black; the
  // label in the bottom row.
  colorBars,
  // Resolution wedges: four fans of lines converging from 8 px to 1 px apart (top, bottom, left,
  // right), a 72-ray star in the centre, a 1-px border and the label (the channel's name).
  wedges,
};

// Draws the pattern; `label` (the channel name) is written on colorBars and wedges. Sizes below
// 1×1 give an empty image.
Image testPattern(TestPattern pattern, int width, int height, const std::string& label);

// "grid", "bars" (or "colorBars"), "wedges"; anything else is an error naming the choices.
Result<TestPattern> parseTestPattern(std::string_view name);

}  // namespace sv::present
