// Integer drawing primitives for the test patterns and the overlay: clipped, exact, no
// anti-aliasing (a projector alignment line must be one pixel, not a smear).
#pragma once

#include <cstdint>

#include "synthvis/image.h"

namespace sv::present::detail {

struct Rgb {
  uint8_t r, g, b;
};

// An image of the size filled with `c` (an empty image when either side is below 1).
Image filledImage(int width, int height, Rgb c);
void putPixel(Image& image, int x, int y, Rgb c);  // ignores pixels outside the image
// The rectangle [x0, x1) × [y0, y1), clipped.
void fillRect(Image& image, int x0, int y0, int x1, int y1, Rgb c);
// Every pixel of the clipped rectangle scaled by num/256 (the overlay's translucent box).
void darkenRect(Image& image, int x0, int y0, int x1, int y1, int num);
// Bresenham's line from (x0, y0) to (x1, y1), both ends included.
void drawLine(Image& image, int x0, int y0, int x1, int y1, Rgb c);
// The midpoint circle of radius r about (cx, cy).
void drawCircle(Image& image, int cx, int cy, int r, Rgb c);

}  // namespace sv::present::detail
