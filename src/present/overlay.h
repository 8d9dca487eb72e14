// Text drawn into a channel: a small built-in 5×7 bitmap font (ASCII 32–126) and the diagnostics
// overlay (per-stage times, degradation level, counts — strings the frame loop makes).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "synthvis/image.h"

namespace sv::present {

// A glyph is 5×7 pixels in a 6×9 cell (one column and two rows of spacing), times `scale`.
inline constexpr int kGlyphWidth = 5, kGlyphHeight = 7, kCellWidth = 6, kCellHeight = 9;

// The 7 rows of a glyph, bit 4 the leftmost column. Characters outside 32–126 draw as '?'.
const uint8_t* glyphRows(char c);

// Draws `text` with its first cell's top-left corner at (x, y); '\n' starts a new line at x.
// Only the glyphs' set pixels are written (the background shows through), clipped to the image.
void drawText(Image& image, int x, int y, std::string_view text, uint8_t r, uint8_t g, uint8_t b,
              int scale = 1);

// The size drawText covers for `text`: (columns of the longest line × kCellWidth − 1) ×
// (lines × kCellHeight − 2), times scale; 0×0 for empty text.
struct TextSize {
  int width = 0, height = 0;
};
TextSize measureText(std::string_view text, int scale = 1);

// A translucent dark box at the top-left corner (the pixels under it darkened to 3/8) with the
// lines in light green, one per row, a 4-px margin.
void drawOverlay(Image& image, std::span<const std::string> lines, int scale = 1);

}  // namespace sv::present
