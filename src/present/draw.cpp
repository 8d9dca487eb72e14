// Based on: Bresenham 1965 (lines: the error term stepped by integer adds); the midpoint circle
// (Pitteway 1967; Foley, van Dam et al., Computer Graphics §3.3.2), eight octants from one.
#include "present/draw.h"

#include <algorithm>
#include <cstdlib>

namespace sv::present::detail {

Image filledImage(int width, int height, Rgb c) {
  Image image;
  if (width < 1 || height < 1) return image;
  image.width = width;
  image.height = height;
  image.rgb.resize(size_t(width) * size_t(height) * 3);
  for (size_t i = 0; i < image.rgb.size(); i += 3) {
    image.rgb[i] = c.r;
    image.rgb[i + 1] = c.g;
    image.rgb[i + 2] = c.b;
  }
  return image;
}

void putPixel(Image& image, int x, int y, Rgb c) {
  if (x < 0 || y < 0 || x >= image.width || y >= image.height) return;
  uint8_t* p = image.pixel(x, y);
  p[0] = c.r;
  p[1] = c.g;
  p[2] = c.b;
}

void fillRect(Image& image, int x0, int y0, int x1, int y1, Rgb c) {
  x0 = std::max(x0, 0), y0 = std::max(y0, 0);
  x1 = std::min(x1, image.width), y1 = std::min(y1, image.height);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) putPixel(image, x, y, c);
}

void darkenRect(Image& image, int x0, int y0, int x1, int y1, int num) {
  x0 = std::max(x0, 0), y0 = std::max(y0, 0);
  x1 = std::min(x1, image.width), y1 = std::min(y1, image.height);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      uint8_t* p = image.pixel(x, y);
      for (int k = 0; k < 3; ++k) p[k] = uint8_t((p[k] * num + 128) >> 8);
    }
}

void drawLine(Image& image, int x0, int y0, int x1, int y1, Rgb c) {
  // One loop for all octants: e = dx + dy is the error of the next pixel from the true line,
  // stepped in x when 2e ≥ dy and in y when 2e ≤ dx.
  const int dx = std::abs(x1 - x0), sx = x0 < x1 ? 1 : -1;
  const int dy = -std::abs(y1 - y0), sy = y0 < y1 ? 1 : -1;
  int e = dx + dy;
  for (;;) {
    putPixel(image, x0, y0, c);
    if (x0 == x1 && y0 == y1) break;
    const int e2 = 2 * e;
    if (e2 >= dy) e += dy, x0 += sx;
    if (e2 <= dx) e += dx, y0 += sy;
  }
}

void drawCircle(Image& image, int cx, int cy, int r, Rgb c) {
  if (r < 0) return;
  // The second octant (x from 0 up to y), mirrored into the other seven; d is the midpoint's
  // decision value, scaled by 4 to stay integral (d = 4·f(x + 1, y − ½)).
  int x = 0, y = r, d = 5 - 4 * r;
  while (x <= y) {
    const int px[8] = {x, y, -x, -y, x, y, -x, -y};
    const int py[8] = {y, x, y, x, -y, -x, -y, -x};
    for (int k = 0; k < 8; ++k) putPixel(image, cx + px[k], cy + py[k], c);
    if (d > 0) {
      d += 8 * (x - y) + 20;
      --y;
    } else {
      d += 8 * x + 12;
    }
    ++x;
  }
}

}  // namespace sv::present::detail
