// Method (b) of issue 34: a flat pinhole image resampled through a display's direction map.
// Based on: issue 34 item 3; the pinhole lens convention of display/geometry.h; Keys 1981, "Cubic
// convolution interpolation for digital image processing" (IEEE Trans. ASSP 29(6)), eq. 15 with
// a = −1/2 — the Catmull–Rom spline's weights.
#include "display/resample.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/quadric.h"

namespace sv::display {
namespace {

constexpr double kToDegrees = 180 / std::numbers::pi;

// v_body = Rᵀ·v_eye: rotationOf gives v_eye = R·v_body, and R is orthonormal.
Vec3d toBody(const Rotation& r, Vec3 d) {
  const double v[3] = {d.x, d.y, d.z};
  double b[3];
  for (int c = 0; c < 3; ++c) b[c] = r.m[0][c] * v[0] + r.m[1][c] * v[1] + r.m[2][c] * v[2];
  return {b[0], b[1], b[2]};
}

// The projection of flatPointOf with the per-view constants set up once.
struct FlatProjection {
  Rotation r;
  WindowTangents t;
  double width, height;
  explicit FlatProjection(const FlatView& v)
      : r(rotationOf(v.orientation)), t(tangentsOf(v.window)), width(v.width), height(v.height) {}
  std::optional<FlatPoint> operator()(Vec3 d) const {
    const Vec3d b = toBody(r, d);
    const double len = std::sqrt(b.x * b.x + b.y * b.y + b.z * b.z);
    // In front: −z strictly positive, beyond rounding (a direction at the horizon has no image).
    if (!(-b.z > 1e-12 * len)) return std::nullopt;
    const double tx = b.x / -b.z, ty = b.y / -b.z;
    return FlatPoint{(tx - t.left) / (t.right - t.left) * width,
                     (t.up - ty) / (t.up - t.down) * height};
  }
};

// Keys's cubic convolution kernel with a = −1/2, as the weights of the four samples at offsets
// −1, 0, 1, 2 from the one left of the point, at fraction f ∈ [0, 1) past it. They sum to one
// for every f (the t³, t² and t terms cancel), so constants and, with the symmetry, lines and
// quadratics are reproduced.
void cubicWeights(float f, float w[4]) {
  const float f2 = f * f, f3 = f2 * f;
  w[0] = -0.5f * f3 + f2 - 0.5f * f;
  w[1] = 1.5f * f3 - 2.5f * f2 + 1;
  w[2] = -1.5f * f3 + 2 * f2 + 0.5f * f;
  w[3] = 0.5f * f3 - 0.5f * f2;
}

// The filtered RGB at continuous flat pixel (px, py) (inside [0, W] × [0, H]), rounded and
// clamped. Sample centres at +0.5: the sample left of p is floor(p − 0.5); samples beyond the
// image's edge repeat the edge. In float: a sum of 16-bit codes carries 24 bits, and the warp's
// points are floats already.
template <ResampleFilter kFilter>
void sample(const uint16_t* rgb, int w, int h, float px, float py, uint16_t* out) {
  constexpr int kTaps = kFilter == ResampleFilter::bilinear ? 2 : 4;
  constexpr int kFirst = kFilter == ResampleFilter::bilinear ? 0 : -1;
  const float u = px - 0.5f, v = py - 0.5f;
  const float iu = std::floor(u), iv = std::floor(v);
  float wx[4], wy[4];
  if constexpr (kFilter == ResampleFilter::bilinear) {
    wx[0] = 1 - (u - iu), wx[1] = u - iu;
    wy[0] = 1 - (v - iv), wy[1] = v - iv;
  } else {
    cubicWeights(u - iu, wx);
    cubicWeights(v - iv, wy);
  }
  int xs[kTaps], ys[kTaps];
  for (int k = 0; k < kTaps; ++k) {
    xs[k] = std::clamp(int(iu) + kFirst + k, 0, w - 1);
    ys[k] = std::clamp(int(iv) + kFirst + k, 0, h - 1);
  }
  float sum[3] = {0, 0, 0};
  for (int j = 0; j < kTaps; ++j) {
    const uint16_t* row = rgb + size_t(ys[j]) * size_t(w) * 3;
    float line[3] = {0, 0, 0};
    for (int i = 0; i < kTaps; ++i)
      for (int c = 0; c < 3; ++c) line[c] += wx[i] * float(row[size_t(xs[i]) * 3 + size_t(c)]);
    for (int c = 0; c < 3; ++c) sum[c] += wy[j] * line[c];
  }
  // Round half up, after the clamp (the cubic's overshoot is negative or past 65535).
  for (int c = 0; c < 3; ++c) out[c] = uint16_t(std::clamp(sum[c], 0.0f, 65535.0f) + 0.5f);
}

template <ResampleFilter kFilter>
void resampleRowsWith(const ResampleWarp& warp, const uint16_t* flatRgb, int y0, int y1,
                      uint16_t* rgb) {
  const FlatView& v = warp.view;
  const size_t w = size_t(warp.width);
  for (size_t i = size_t(y0) * w; i < size_t(y1) * w; ++i) {
    uint16_t* out = rgb + 3 * i;
    if (!warp.lands(i)) {
      out[0] = out[1] = out[2] = 0;
      continue;
    }
    sample<kFilter>(flatRgb, v.width, v.height, warp.points[2 * i], warp.points[2 * i + 1], out);
  }
}

}  // namespace

std::optional<FlatPoint> flatPointOf(const FlatView& view, Vec3 direction) {
  return FlatProjection(view)(direction);
}

ResampleWarp resampleWarp(const FlatView& view, const DirectionMap& display) {
  ResampleWarp warp;
  warp.view = view;
  warp.width = display.width;
  warp.height = display.height;
  warp.points.assign(size_t(display.width) * size_t(display.height) * 2,
                     std::numeric_limits<float>::quiet_NaN());
  const FlatProjection project(view);
  for (int y = 0; y < display.height; ++y)
    for (int x = 0; x < display.width; ++x) {
      if (!display.isValid(x, y)) {
        ++warp.invalid;
        continue;
      }
      const std::optional<FlatPoint> p = project(display.direction(x, y));
      // Inside the image's rectangle (a NaN fails every comparison, so lands outside).
      if (!p || !(p->x >= 0 && p->x <= view.width && p->y >= 0 && p->y <= view.height)) {
        ++warp.outside;
        continue;
      }
      const size_t i = size_t(y) * size_t(display.width) + size_t(x);
      warp.points[2 * i] = float(p->x);
      warp.points[2 * i + 1] = float(p->y);
    }
  return warp;
}

void resampleRows(const ResampleWarp& warp, const uint16_t* flatRgb, ResampleFilter filter, int y0,
                  int y1, uint16_t* rgb) {
  if (filter == ResampleFilter::bilinear)
    resampleRowsWith<ResampleFilter::bilinear>(warp, flatRgb, y0, y1, rgb);
  else
    resampleRowsWith<ResampleFilter::bicubic>(warp, flatRgb, y0, y1, rgb);
}

ResampledImage resampleFlatImage(const FlatView& view, const uint16_t* flatRgb,
                                 const DirectionMap& display, ResampleFilter filter) {
  const ResampleWarp warp = resampleWarp(view, display);
  ResampledImage image;
  image.width = display.width;
  image.height = display.height;
  image.rgb.resize(size_t(display.width) * size_t(display.height) * 3);
  resampleRows(warp, flatRgb, filter, 0, display.height, image.rgb.data());
  image.outside = warp.outside;
  image.invalid = warp.invalid;
  return image;
}

double finestAngularPixel(const DirectionMap& display) {
  double finest = 0;
  bool any = false;
  for (int y = 0; y < display.height; ++y)
    for (int x = 0; x < display.width; ++x) {
      if (!display.isValid(x, y)) continue;
      for (const auto& [nx, ny] : {std::pair{x + 1, y}, std::pair{x, y + 1}}) {
        if (nx >= display.width || ny >= display.height || !display.isValid(nx, ny)) continue;
        const Vec3 p = display.direction(x, y), q = display.direction(nx, ny);
        const double a = angleBetween(Vec3d{p.x, p.y, p.z}, Vec3d{q.x, q.y, q.z});
        if (!any || a < finest) finest = a;
        any = true;
      }
    }
  return finest;
}

Orientation meanOrientation(const DirectionMap& display) {
  double s[3] = {0, 0, 0};
  for (size_t i = 0; i < display.directions.size(); ++i) {
    if (!display.valid[i]) continue;
    s[0] += display.directions[i].x;
    s[1] += display.directions[i].y;
    s[2] += display.directions[i].z;
  }
  const double len = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
  if (!(len > 0)) return {};
  // rotationOf(yaw, pitch, 0) looks along (sin yaw · cos pitch, sin pitch, −cos yaw · cos pitch).
  Orientation o;
  o.yawDegrees = std::atan2(s[0], -s[2]) * kToDegrees;
  o.pitchDegrees = std::asin(std::clamp(s[1] / len, -1.0, 1.0)) * kToDegrees;
  return o;
}

Result<FlatView> coveringFlatView(const DirectionMap& display, const Orientation& orientation,
                                  int marginPixels, int maxSide) {
  // Step 1: the tangent rectangle of every valid direction in the orientation's image plane.
  const Rotation r = rotationOf(orientation);
  double left = 0, right = 0, down = 0, up = 0;
  bool any = false;
  for (int y = 0; y < display.height; ++y)
    for (int x = 0; x < display.width; ++x) {
      if (!display.isValid(x, y)) continue;
      const Vec3d b = toBody(r, display.direction(x, y));
      const double len = std::sqrt(b.x * b.x + b.y * b.y + b.z * b.z);
      if (!(-b.z > 1e-12 * len))
        return Error{"", "",
                     fmt::format("display pixel ({}, {}) looks behind or beside the flat "
                                 "camera's orientation: no flat window holds it",
                                 x, y)};
      const double tx = b.x / -b.z, ty = b.y / -b.z;
      left = any ? std::min(left, tx) : tx;
      right = any ? std::max(right, tx) : tx;
      down = any ? std::min(down, ty) : ty;
      up = any ? std::max(up, ty) : ty;
      any = true;
    }
  if (!any) return Error{"", "", "the display has no valid pixel"};
  // Step 2: the tangent step, at most the finest angular pixel; the margin in that step.
  const double finest = finestAngularPixel(display);
  if (!(finest > 0))
    return Error{"", "", "the display has no two valid neighbouring pixels to measure a pixel by"};
  const double innerW = std::max(1.0, std::ceil((right - left) / finest));
  const double innerH = std::max(1.0, std::ceil((up - down) / finest));
  if (innerW + 2.0 * marginPixels > maxSide || innerH + 2.0 * marginPixels > maxSide)
    return Error{"", "",
                 fmt::format("the flat view would need {} × {} pixels, more than {} a side",
                             innerW + 2 * marginPixels, innerH + 2 * marginPixels, maxSide)};
  // Centre the rounding up: the inner rectangle keeps its middle.
  const double stepX = finest, stepY = finest;
  const double midX = 0.5 * (left + right), midY = 0.5 * (down + up);
  const double halfW = 0.5 * innerW * stepX + marginPixels * stepX;
  const double halfH = 0.5 * innerH * stepY + marginPixels * stepY;
  FlatView v;
  v.orientation = orientation;
  v.window.leftDegrees = std::atan(midX - halfW) * kToDegrees;
  v.window.rightDegrees = std::atan(midX + halfW) * kToDegrees;
  v.window.downDegrees = std::atan(midY - halfH) * kToDegrees;
  v.window.upDegrees = std::atan(midY + halfH) * kToDegrees;
  v.width = int(innerW) + 2 * marginPixels;
  v.height = int(innerH) + 2 * marginPixels;
  return v;
}

}  // namespace sv::display
