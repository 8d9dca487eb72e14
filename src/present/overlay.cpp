// The overlay's text: glyphs from font5x7.cpp, each set bit a scale×scale block.
#include "present/overlay.h"

#include <algorithm>

#include "present/draw.h"

namespace sv::present {

void drawText(Image& image, int x, int y, std::string_view text, uint8_t r, uint8_t g, uint8_t b,
              int scale) {
  scale = std::max(scale, 1);
  const detail::Rgb c{r, g, b};
  int cx = x, cy = y;
  for (char ch : text) {
    if (ch == '\n') {
      cx = x;
      cy += kCellHeight * scale;
      continue;
    }
    const uint8_t* rows = glyphRows(ch);
    for (int row = 0; row < kGlyphHeight; ++row)
      for (int col = 0; col < kGlyphWidth; ++col)
        if (rows[row] & (0x10 >> col))
          detail::fillRect(image, cx + col * scale, cy + row * scale, cx + (col + 1) * scale,
                           cy + (row + 1) * scale, c);
    cx += kCellWidth * scale;
  }
}

TextSize measureText(std::string_view text, int scale) {
  scale = std::max(scale, 1);
  if (text.empty()) return {};
  int lines = 1, columns = 0, widest = 0;
  for (char ch : text) {
    if (ch == '\n') {
      ++lines;
      columns = 0;
    } else {
      widest = std::max(widest, ++columns);
    }
  }
  // The last column's and row's spacing is not part of the text.
  return {widest > 0 ? (widest * kCellWidth - 1) * scale : 0, (lines * kCellHeight - 2) * scale};
}

void drawOverlay(Image& image, std::span<const std::string> lines, int scale) {
  if (lines.empty()) return;
  scale = std::max(scale, 1);
  const int margin = 4 * scale;
  int width = 0;
  for (const std::string& line : lines) width = std::max(width, measureText(line, scale).width);
  const int height = (int(lines.size()) * kCellHeight - 2) * scale;
  // Dark enough for light text on a bright sky, light enough to see the scene under it.
  detail::darkenRect(image, 0, 0, width + 2 * margin, height + 2 * margin, 96);
  for (size_t i = 0; i < lines.size(); ++i)
    drawText(image, margin, margin + int(i) * kCellHeight * scale, lines[i], 160, 255, 160, scale);
}

}  // namespace sv::present
