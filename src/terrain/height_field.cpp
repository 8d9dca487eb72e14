// Based on: SPEC §11 (height tables, bilinear or bicubic interpolation below the finest level).
#include "terrain/height_field.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace sv::terrain {

Result<Interpolation> parseInterpolation(const std::string& name) {
  if (name == "bilinear") return Interpolation::bilinear;
  if (name == "bicubic") return Interpolation::bicubic;
  return Error{"", "", fmt::format("unknown interpolation '{}' (bilinear or bicubic)", name)};
}

const char* interpolationName(Interpolation i) {
  return i == Interpolation::bicubic ? "bicubic" : "bilinear";
}

namespace {

// Catmull–Rom weights at t ∈ [0, 1] for samples −1, 0, 1, 2, and their derivatives.
void catmullRom(double t, double w[4], double dw[4]) {
  const double t2 = t * t, t3 = t2 * t;
  w[0] = 0.5 * (-t3 + 2 * t2 - t);
  w[1] = 0.5 * (3 * t3 - 5 * t2 + 2);
  w[2] = 0.5 * (-3 * t3 + 4 * t2 + t);
  w[3] = 0.5 * (t3 - t2);
  dw[0] = 0.5 * (-3 * t2 + 4 * t - 1);
  dw[1] = 0.5 * (9 * t2 - 10 * t);
  dw[2] = 0.5 * (-9 * t2 + 8 * t + 1);
  dw[3] = 0.5 * (3 * t2 - 2 * t);
}

}  // namespace

double interpolate(const HeightField& f, Interpolation interp, double x, double y, double* dx,
                   double* dy) {
  x = std::clamp(x, 0.0, double(f.width - 1));
  y = std::clamp(y, 0.0, double(f.height - 1));
  // The cell (i, j) … (i + 1, j + 1) holding (x, y); the last row and column belong to the cell
  // before them (so t = 1 there, and the grid point is still reproduced exactly).
  const int i = std::min(int(x), f.width - 2), j = std::min(int(y), f.height - 2);
  const double s = x - i, t = y - j;
  if (interp == Interpolation::bilinear) {
    const double h00 = f.code(i, j), h10 = f.code(i + 1, j), h01 = f.code(i, j + 1),
                 h11 = f.code(i + 1, j + 1);
    const double top = h00 + (h10 - h00) * s, bottom = h01 + (h11 - h01) * s;
    if (dx) *dx = f.scale * ((h10 - h00) * (1 - t) + (h11 - h01) * t);
    if (dy) *dy = f.scale * (bottom - top);
    return f.offset + f.scale * (top + (bottom - top) * t);
  }
  double wx[4], dwx[4], wy[4], dwy[4];
  catmullRom(s, wx, dwx);
  catmullRom(t, wy, dwy);
  double h[4][4];
  cellSamples(f, i, j, h);
  double v = 0, vx = 0, vy = 0;
  for (int r = 0; r < 4; ++r) {
    double a = 0, ad = 0;
    for (int c = 0; c < 4; ++c) {
      a += wx[c] * h[r][c];
      ad += dwx[c] * h[r][c];
    }
    v += wy[r] * a;
    vx += wy[r] * ad;
    vy += dwy[r] * a;
  }
  if (dx) *dx = f.scale * vx;
  if (dy) *dy = f.scale * vy;
  return f.offset + f.scale * v;
}

void cellSamples(const HeightField& f, int i, int j, double h[4][4]) {
  for (int y = 0; y < 4; ++y) {
    const uint16_t* row =
        f.q.data() + size_t(std::clamp(j - 1 + y, 0, f.height - 1)) * size_t(f.width);
    for (int x = 0; x < 4; ++x) h[y][x] = row[std::clamp(i - 1 + x, 0, f.width - 1)];
  }
}

double bezierTop(const double h[4][4]) {
  auto bezier = [](const double p[4], double b[4]) {
    b[0] = p[1], b[1] = p[1] + (p[2] - p[0]) / 6, b[2] = p[2] - (p[3] - p[1]) / 6, b[3] = p[2];
  };
  double rows[4][4], top = -std::numeric_limits<double>::infinity();
  for (int y = 0; y < 4; ++y) bezier(h[y], rows[y]);
  for (int x = 0; x < 4; ++x) {
    const double column[4] = {rows[0][x], rows[1][x], rows[2][x], rows[3][x]};
    double b[4];
    bezier(column, b);
    top = std::max({top, b[0], b[1], b[2], b[3]});
  }
  return top;
}

}  // namespace sv::terrain
