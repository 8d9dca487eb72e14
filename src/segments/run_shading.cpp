// Based on: SPEC §10 (seed 002: intensity interpolated along the run), §2 (colour/w ÷ 1/w);
// geometry/setup.h planeAtPixel and raster/kernel_common-inl.h (blockBases, colorToLanes): the same
// float operations in the same order per pixel, here a row's pixels in lanes.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "segments/run_shading.cpp"
#include "segments/run_shading.h"

#include <algorithm>

#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"

HWY_BEFORE_NAMESPACE();
namespace sv::segments {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

void ShadeRun(const geometry::TriangleSetup& t, int y, int xa, int xb, uint16_t* rgb) {
  const hn::ScalableTag<float> df;
  const hn::RebindToSigned<decltype(df)> di;
  const size_t n = hn::Lanes(df);
  const float by = float((y & ~3) - t.minY), ly = float(y & 3);
  const geometry::Plane* planes[4] = {&t.invW, &t.red, &t.green, &t.blue};
  // Per plane: c0 and dx broadcast, dy·by and dy·ly once for the row.
  hn::Vec<decltype(df)> c0[4], dx[4], dyBy[4], dyLy[4];
  for (int p = 0; p < 4; ++p) {
    c0[p] = hn::Set(df, planes[p]->c0);
    dx[p] = hn::Set(df, planes[p]->dx);
    dyBy[p] = hn::Set(df, planes[p]->dy * by);
    dyLy[p] = hn::Set(df, planes[p]->dy * ly);
  }
  const auto one = hn::Set(df, 1.0f), zero = hn::Zero(df), scale = hn::Set(df, 65535.0f);
  const auto magic = hn::Set(df, 8388608.0f);
  HWY_ALIGN int32_t codes[3][hn::MaxLanes(di)];
  for (int x = xa; x < xb; x += int(n)) {
    const auto xs = hn::Iota(di, x);
    const auto bx = hn::ConvertTo(df, hn::Sub(hn::And(xs, hn::Set(di, ~3)), hn::Set(di, t.minX)));
    const auto lx = hn::ConvertTo(df, hn::And(xs, hn::Set(di, 3)));
    // (c0 + dx·bx) + dy·by, plus dx·lx + dy·ly: planeAtPixel's base and offset.
    const auto at = [&](int p) {
      return hn::Add(hn::Add(hn::Add(c0[p], hn::Mul(dx[p], bx)), dyBy[p]),
                     hn::Add(hn::Mul(dx[p], lx), dyLy[p]));
    };
    const auto w = hn::Div(one, at(0));
    for (int c = 0; c < 3; ++c) {
      const auto v = hn::Min(hn::Max(hn::Mul(at(c + 1), w), zero), one);
      hn::Store(hn::And(hn::BitCast(di, hn::Add(hn::Mul(v, scale), magic)), hn::Set(di, 0xFFFF)),
                di, codes[c]);
    }
    const int count = std::min(int(n), xb - x);
    uint16_t* out = rgb + 3 * (x - xa);
    for (int i = 0; i < count; ++i) {
      out[3 * i] = uint16_t(codes[0][i]);
      out[3 * i + 1] = uint16_t(codes[1][i]);
      out[3 * i + 2] = uint16_t(codes[2][i]);
    }
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::segments
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sv::segments {
HWY_EXPORT(ShadeRun);

void shadeRun(const geometry::TriangleSetup& t, int y, int xa, int xb, uint16_t* rgb) {
  HWY_DYNAMIC_DISPATCH(ShadeRun)(t, y, xa, xb, rgb);
}

}  // namespace sv::segments
#endif
