// sizeSplats (splat_sizes.h): light_laws.h's size, weights and energy of 16 lights at a time, in
// lanes; each lane's arithmetic the scalar reference's, operation for operation (no fused
// multiply-adds: -ffp-contract=off), so every target gives the same bits.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "lights/splat_sizes.cpp"
// clang-format off: foreach_target.h first
#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"
// clang-format on

#include <algorithm>
#include <cmath>

#include "lights/light_laws.h"
#include "lights/splat_sizes.h"

HWY_BEFORE_NAMESPACE();
namespace sv::lights {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using DF = hn::ScalableTag<float>;
using DI = hn::RebindToSigned<DF>;
using VF = hn::Vec<DF>;
using VI = hn::Vec<DI>;

// floorToInt (light_laws.h) in lanes: the truncation, less one where it rounded up.
HWY_INLINE VI FloorToInt(VF x) {
  const DF df;
  const DI di;
  const VI i = hn::ConvertTo(di, x);
  return hn::Sub(
      i, hn::IfThenElseZero(hn::RebindMask(di, hn::Gt(hn::ConvertTo(df, i), x)), hn::Set(di, 1)));
}

// splatWeight of the pixel centre first + k about c: (1 − d²/R²)², 0 from R on.
HWY_INLINE VF AxisWeight(VI first, int k, VF c, VF invR2) {
  const DF df;
  const DI di;
  const VF d =
      hn::Sub(hn::Add(hn::ConvertTo(df, hn::Add(first, hn::Set(di, k))), hn::Set(df, 0.5f)), c);
  const VF u = hn::Sub(hn::Set(df, 1.0f), hn::Mul(hn::Mul(d, d), invR2));
  return hn::IfThenElseZero(hn::Gt(u, hn::Zero(df)), hn::Mul(u, u));
}

// One axis: the first centre, the span (at most kMaxSplatSpan), the first four weights and the
// sum of the weights within the span (splatAxis4, splatAxis: a lane past its span adds nothing).
HWY_INLINE VF Axis(VF c, VF radius, VF invR2, VI& first, VI& span, VF kept[4]) {
  const DF df;
  const DI di;
  first = FloorToInt(hn::Sub(c, radius));
  span = hn::Min(hn::Add(hn::Sub(FloorToInt(hn::Add(c, radius)), first), hn::Set(di, 1)),
                 hn::Set(di, kMaxSplatSpan));
  VF sum = hn::Zero(df);
  for (int k = 0; k < 4; ++k) {
    kept[k] = AxisWeight(first, k, c, invR2);
    sum = hn::Add(sum, kept[k]);  // past the span a weight is 0: adding it keeps the sum's bits
  }
  const int longest = hn::GetLane(hn::MaxOfLanes(di, span));
  for (int k = 4; k < longest; ++k) {
    const VF w = AxisWeight(first, k, c, invR2);
    sum = hn::Add(sum, hn::IfThenElseZero(hn::RebindMask(df, hn::Lt(hn::Set(di, k), span)), w));
  }
  return sum;
}

void SizeSplats(const SizeLaws& laws, int count, SizeBatch& b) {
  const DF df;
  const DI di;
  const size_t n = hn::Lanes(df);
  for (size_t i = 0; i < size_t(count); i += n) {
    const VF energy = hn::Load(df, b.energy + i);
    const VF r = hn::Load(df, b.r + i), g = hn::Load(df, b.g + i), bl = hn::Load(df, b.b + i);
    const VF x = hn::Load(df, b.x + i), y = hn::Load(df, b.y + i);
    // Dark: it adds less than half a 16-bit step to every pixel (at its brightest channel).
    const VF peak = hn::Mul(hn::Mul(energy, hn::Max(hn::Max(r, g), bl)), hn::Set(df, 65535.0f));
    auto drawn = hn::Ge(peak, hn::Set(df, 0.5f));
    // splatRadius(splatDiameter(Φ)): std::clamp's comparisons, in its order.
    const VF natural =
        hn::Sub(hn::Mul(hn::Set(df, 2 * (15.0f / 16)), hn::Sqrt(energy)), hn::Set(df, 1.0f));
    const VF lo = hn::Set(df, laws.minSize), hi = hn::Set(df, laws.maxSize);
    const VF diameter =
        hn::IfThenElse(hn::Lt(natural, lo), lo, hn::IfThenElse(hn::Lt(hi, natural), hi, natural));
    const VF radius = hn::Add(hn::Mul(hn::Set(df, 0.5f), diameter), hn::Set(df, 0.5f));
    const VF zero = hn::Zero(df);
    const auto off =
        hn::Or(hn::Or(hn::Lt(hn::Add(x, radius), zero), hn::Lt(hn::Add(y, radius), zero)),
               hn::Or(hn::Gt(hn::Sub(x, radius), hn::Set(df, laws.width)),
                      hn::Gt(hn::Sub(y, radius), hn::Set(df, laws.height))));
    drawn = hn::AndNot(off, drawn);
    const VF invR2 = hn::Div(hn::Set(df, 1.0f), hn::Mul(radius, radius));
    VI firstX, firstY, spanX, spanY;
    VF kx[4], ky[4];
    const VF sx = Axis(x, radius, invR2, firstX, spanX, kx);
    const VF sy = Axis(y, radius, invR2, firstY, spanY, ky);
    // The four weights kept where both spans are at most four (a larger splat's are worked out
    // again where it is drawn).
    const VI five = hn::Set(di, 5);
    const auto keep = hn::RebindMask(df, hn::And(hn::Lt(spanX, five), hn::Lt(spanY, five)));
    for (int k = 0; k < 4; ++k) {
      hn::Store(hn::IfThenElseZero(keep, kx[k]), df, b.kx[k] + i);
      hn::Store(hn::IfThenElseZero(keep, ky[k]), df, b.ky[k] + i);
    }
    // The colour scaled so that the weights carry Φ, capped where it saturates anyway.
    const VF scale = hn::Div(hn::Mul(energy, hn::Set(df, 65535.0f)), hn::Mul(sx, sy));
    const VF cap = hn::Set(df, 1e6f);
    hn::Store(hn::Min(hn::Mul(r, scale), cap), df, b.red + i);
    hn::Store(hn::Min(hn::Mul(g, scale), cap), df, b.green + i);
    hn::Store(hn::Min(hn::Mul(bl, scale), cap), df, b.blue + i);
    // The window depth depthBias in front of the light (a star: 1; in front of the eye: −1).
    const VF eyeDepth = hn::Load(df, b.eyeDepth + i);
    const VF front = hn::Sub(eyeDepth, hn::Set(df, laws.depthBias));
    const auto ahead = hn::Gt(front, zero);
    const VF window =
        hn::Add(hn::Mul(hn::Set(df, 0.5f),
                        hn::Add(hn::Set(df, -laws.m22),
                                hn::Div(hn::Set(df, laws.m32),
                                        hn::IfThenElse(ahead, front, hn::Set(df, 1.0f))))),
                hn::Set(df, 0.5f));
    hn::Store(hn::IfThenElse(hn::Eq(eyeDepth, zero), hn::Set(df, 1.0f),
                             hn::IfThenElse(ahead, window, hn::Set(df, -1.0f))),
              df, b.frontDepth + i);
    hn::Store(radius, df, b.radius + i);
    hn::Store(firstX, di, b.firstX + i);
    hn::Store(firstY, di, b.firstY + i);
    hn::Store(spanX, di, b.spanX + i);
    hn::Store(spanY, di, b.spanY + i);
    hn::Store(hn::IfThenElseZero(hn::RebindMask(di, drawn), hn::Set(di, 1)), di, b.drawn + i);
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::lights
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sv::lights {
HWY_EXPORT(SizeSplats);

void sizeSplats(const SizeLaws& laws, int count, SizeBatch& batch) {
  count = std::clamp(count, 0, SizeBatch::kLights);
  if (count == 0) return;
  // Lanes past `count` size a copy of the first light (whole vectors are read).
  for (int i = count; i < SizeBatch::kLights; ++i) {
    batch.x[i] = batch.x[0], batch.y[i] = batch.y[0], batch.energy[i] = batch.energy[0];
    batch.r[i] = batch.r[0], batch.g[i] = batch.g[0], batch.b[i] = batch.b[0];
    batch.eyeDepth[i] = batch.eyeDepth[0];
  }
  HWY_DYNAMIC_DISPATCH(SizeSplats)(laws, count, batch);
}

bool sizeSplat(const SizeLaws& laws, SizeBatch& b, int i) {
  // (The pass's own way before the lanes, line for line; outputs past a cull are unset.)
  const float energy = b.energy[i];
  const Vec3 color{b.r[i], b.g[i], b.b[i]};
  b.drawn[i] = 0;
  const float peak = energy * std::max({color.x, color.y, color.z}) * 65535;
  if (!(peak >= 0.5f)) return false;
  const float radius = splatRadius(splatDiameter(energy, laws.minSize, laws.maxSize));
  const float x = b.x[i], y = b.y[i];
  if (x + radius < 0 || y + radius < 0 || x - radius > laws.width || y - radius > laws.height)
    return false;
  b.radius[i] = radius;
  // The weight sum, a product of the two axes' sums (light_laws.h: splatWeightSum), from the
  // axis weights a small splat keeps for drawing.
  float sx = 0, sy = 0, kx[4] = {}, ky[4] = {};
  if (radius <= kSmallSplatRadius) {
    b.spanX[i] = splatAxis4(x, radius, kx, b.firstX[i]);
    b.spanY[i] = splatAxis4(y, radius, ky, b.firstY[i]);
    for (int k = 0; k < 4; ++k) sx += kx[k];  // + 0 past the span: the same sum
    for (int k = 0; k < 4; ++k) sy += ky[k];
  } else {
    float wx[kMaxSplatSpan], wy[kMaxSplatSpan];
    b.spanX[i] = splatAxis(x, radius, wx, b.firstX[i]);
    b.spanY[i] = splatAxis(y, radius, wy, b.firstY[i]);
    for (int k = 0; k < b.spanX[i]; ++k) sx += wx[k];
    for (int k = 0; k < b.spanY[i]; ++k) sy += wy[k];
    if (b.spanX[i] <= 4 && b.spanY[i] <= 4) {
      std::copy_n(wx, b.spanX[i], kx);
      std::copy_n(wy, b.spanY[i], ky);
    }
  }
  const bool keep = b.spanX[i] <= 4 && b.spanY[i] <= 4;
  for (int k = 0; k < 4; ++k) b.kx[k][i] = keep ? kx[k] : 0, b.ky[k][i] = keep ? ky[k] : 0;
  const float scale = energy * 65535 / (sx * sy);
  // A weight-1 pixel's addition, capped where it saturates anyway (so that it converts to int).
  b.red[i] = std::min(color.x * scale, 1e6f);
  b.green[i] = std::min(color.y * scale, 1e6f);
  b.blue[i] = std::min(color.z * scale, 1e6f);
  // The window depth at depthBias in front of the light: a sample no nearer cannot hide it.
  const float front = b.eyeDepth[i] - laws.depthBias;
  b.frontDepth[i] = b.eyeDepth[i] == 0 ? 1.0f
                    : front > 0        ? 0.5f * (-laws.m22 + laws.m32 / front) + 0.5f
                                       : -1.0f;
  b.drawn[i] = 1;
  return true;
}

}  // namespace sv::lights
#endif
