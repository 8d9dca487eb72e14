// Based on: SPEC §7 (the footprint's level of detail), §8, §11.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "terrain/shade_lanes.cpp"
// clang-format off: foreach_target.h first
#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"
// clang-format on

#include "core/lane_math-inl.h"
#include "terrain/shade_lanes.h"

HWY_BEFORE_NAMESPACE();
namespace sv::terrain {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

template <class DF>
using VF = hn::Vec<DF>;

// Catmull–Rom's weights at t for the samples −1 … 2, and their derivatives (height_field.cpp).
template <class DF>
void CatmullRom(DF df, VF<DF> t, VF<DF> w[4], VF<DF> dw[4]) {
  const VF<DF> half = hn::Set(df, 0.5f), t2 = hn::Mul(t, t), t3 = hn::Mul(t2, t);
  auto k = [&](float v) { return hn::Set(df, v); };
  auto poly = [&](float c3, float c2, float c1, float c0) {  // ½·(c3·t³ + c2·t² + c1·t + c0)
    return hn::Mul(half, hn::Add(hn::Add(hn::Mul(k(c3), t3), hn::Mul(k(c2), t2)),
                                 hn::Add(hn::Mul(k(c1), t), k(c0))));
  };
  w[0] = poly(-1, 2, -1, 0), w[1] = poly(3, -5, 0, 2), w[2] = poly(-3, 4, 1, 0),
  w[3] = poly(1, -1, 0, 0);
  dw[0] = poly(0, -3, 4, -1), dw[1] = poly(0, 9, -10, 0), dw[2] = poly(0, -9, 8, 1),
  dw[3] = poly(0, 3, -2, 0);
}

template <class DF>
VF<DF> Dot(VF<DF> ax, VF<DF> ay, VF<DF> az, VF<DF> bx, VF<DF> by, VF<DF> bz) {
  return hn::Add(hn::Add(hn::Mul(ax, bx), hn::Mul(ay, by)), hn::Mul(az, bz));
}

void ShadeLanesKernel(const ShadeFrame& f, const ShadeLanes& L, shade::Fragments& frag,
                      shade::TexCoords& tc) {
  const hn::CappedTag<float, shade::kMaxFragments> df;
  using V = VF<decltype(df)>;
  const V zero = hn::Zero(df), one = hn::Set(df, 1.0f), half = hn::Set(df, 0.5f);
  auto set3 = [&](const float* v, V* out) {
    for (int k = 0; k < 3; ++k) out[k] = hn::Set(df, v[k]);
  };
  V d0[3], dX[3], dY[3], right[3], up[3], forward[3];
  set3(f.d0, d0), set3(f.dX, dX), set3(f.dY, dY);
  set3(f.right, right), set3(f.up, up), set3(f.forward, forward);
  for (size_t i = 0; i < size_t(frag.count); i += hn::Lanes(df)) {
    const V px = hn::Load(df, L.px + i), py = hn::Load(df, L.py + i), s = hn::Load(df, L.s + i);
    V d[3], rel[3];
    for (int k = 0; k < 3; ++k) {
      d[k] = hn::Add(hn::Add(d0[k], hn::Mul(dX[k], px)), hn::Mul(dY[k], py));
      rel[k] = hn::Mul(d[k], s);
    }
    // The normal of the bilinear surface met (Caster::normal on the plane): its slopes per grid
    // step in codes, per metre east and north, then (−∂h/∂east, 1, ∂h/∂north) normalized (north
    // is −z).
    const V u = hn::Load(df, L.cellU + i), v = hn::Load(df, L.cellV + i);
    const V h00 = hn::Load(df, L.h00 + i), h10 = hn::Load(df, L.h10 + i);
    const V h01 = hn::Load(df, L.h01 + i), h11 = hn::Load(df, L.h11 + i);
    const V step = hn::Load(df, L.step + i);
    const V top = hn::Add(h00, hn::Mul(hn::Sub(h10, h00), u));
    const V bottom = hn::Add(h01, hn::Mul(hn::Sub(h11, h01), u));
    V slopeX = hn::Div(
        hn::Add(hn::Mul(hn::Sub(h10, h00), hn::Sub(one, v)), hn::Mul(hn::Sub(h11, h01), v)), step);
    V slopeY = hn::Div(hn::Sub(bottom, top), step);
    if (L.bicubic) {
      // interpolate (height_field.cpp): ∂P/∂u = Σ_y w_y(v)·Σ_x w'_x(u)·h[y][x], ∂P/∂v likewise;
      // the samples relative to the cell's own (the weights' derivatives sum to 0).
      V wu[4], dwu[4], wv[4], dwv[4];
      CatmullRom(df, u, wu, dwu);
      CatmullRom(df, v, wv, dwv);
      const V ref = hn::Load(df, L.patch[5] + i);
      V du = zero, dv = zero;
      for (int y = 0; y < 4; ++y) {
        V row = zero, rowD = zero;
        for (int x = 0; x < 4; ++x) {
          const V h = hn::Sub(hn::Load(df, L.patch[4 * y + x] + i), ref);
          row = hn::Add(row, hn::Mul(wu[x], h));
          rowD = hn::Add(rowD, hn::Mul(dwu[x], h));
        }
        du = hn::Add(du, hn::Mul(wv[y], rowD));
        dv = hn::Add(dv, hn::Mul(dwv[y], row));
      }
      const auto cubic = hn::Gt(hn::Load(df, L.cubic + i), zero);
      slopeX = hn::IfThenElse(cubic, du, slopeX);
      slopeY = hn::IfThenElse(cubic, dv, slopeY);
    }
    const V se = hn::Mul(slopeX, hn::Set(df, f.scale / f.spacingU));
    const V sn = hn::Neg(hn::Mul(slopeY, hn::Set(df, f.scale / f.spacingV)));
    const V inv = hn::Div(one, hn::Sqrt(hn::Add(hn::Add(hn::Mul(se, se), one), hn::Mul(sn, sn))));
    const V n[3] = {hn::Neg(hn::Mul(se, inv)), inv, hn::Mul(sn, inv)};
    const V eyeX = Dot<decltype(df)>(rel[0], rel[1], rel[2], right[0], right[1], right[2]);
    const V eyeY = Dot<decltype(df)>(rel[0], rel[1], rel[2], up[0], up[1], up[2]);
    const V eyeZ =
        hn::Neg(Dot<decltype(df)>(rel[0], rel[1], rel[2], forward[0], forward[1], forward[2]));
    hn::Store(eyeX, df, frag.attribute[shade::kEyeX] + i);
    hn::Store(eyeY, df, frag.attribute[shade::kEyeY] + i);
    hn::Store(eyeZ, df, frag.attribute[shade::kEyeZ] + i);
    hn::Store(Dot<decltype(df)>(n[0], n[1], n[2], right[0], right[1], right[2]), df,
              frag.attribute[shade::kNormalX] + i);
    hn::Store(Dot<decltype(df)>(n[0], n[1], n[2], up[0], up[1], up[2]), df,
              frag.attribute[shade::kNormalY] + i);
    hn::Store(hn::Neg(Dot<decltype(df)>(n[0], n[1], n[2], forward[0], forward[1], forward[2])), df,
              frag.attribute[shade::kNormalZ] + i);
    if (!f.image) continue;
    const V gx = hn::Load(df, L.gx + i), gy = hn::Load(df, L.gy + i);
    hn::Store(hn::Add(hn::Mul(gx, hn::Set(df, f.texX)), hn::Set(df, f.texX0)), df, tc.x0 + i);
    hn::Store(hn::Add(hn::Mul(gy, hn::Set(df, f.texY)), hn::Set(df, f.texY0)), df, tc.y0 + i);
    if (f.levelZero) {
      hn::Store(zero, df, tc.lod + i);
      continue;
    }
    // The footprint: where the next pixel's rays, right and down, meet the tangent plane at the
    // hit — map metres east (x) and north (−z) per pixel.
    const V nRel = Dot<decltype(df)>(n[0], n[1], n[2], rel[0], rel[1], rel[2]);
    V du[2], dv[2];
    auto finite = hn::Eq(zero, zero);
    for (int axis = 0; axis < 2; ++axis) {
      const V* next = axis == 0 ? dX : dY;
      const V dn[3] = {hn::Add(d[0], next[0]), hn::Add(d[1], next[1]), hn::Add(d[2], next[2])};
      const V den = Dot<decltype(df)>(n[0], n[1], n[2], dn[0], dn[1], dn[2]);
      const V tt = hn::Div(nRel, den);
      finite =
          hn::And(finite, hn::And(hn::Gt(hn::Abs(den), hn::Set(df, 1e-12f)),
                                  hn::And(hn::Gt(tt, zero), hn::Lt(tt, hn::Set(df, 3.0e38f)))));
      du[axis] = hn::Sub(hn::Mul(dn[0], tt), rel[0]);
      dv[axis] = hn::Neg(hn::Sub(hn::Mul(dn[2], tt), rel[2]));
    }
    const V far = hn::Set(df, 1e9f);
    const V pmX = hn::Set(df, f.perMetreX), pmY = hn::Set(df, f.perMetreY);
    // lodOf (terrain_pass.cpp): ½·log2 σ₁² of the texel Jacobian [a b; c d], at least 0.
    const V a = hn::Mul(hn::IfThenElse(finite, du[0], far), pmX);
    const V b = hn::Mul(hn::IfThenElse(finite, du[1], far), pmX);
    const V c = hn::Neg(hn::Mul(hn::IfThenElse(finite, dv[0], far), pmY));
    const V e = hn::Neg(hn::Mul(hn::IfThenElse(finite, dv[1], far), pmY));
    const V sum =
        hn::Add(hn::Add(hn::Add(hn::Mul(a, a), hn::Mul(b, b)), hn::Mul(c, c)), hn::Mul(e, e));
    const V det = hn::Sub(hn::Mul(a, e), hn::Mul(b, c));
    const V major2 = hn::Mul(
        half, hn::Add(sum, hn::Sqrt(hn::Max(hn::Sub(hn::Mul(sum, sum),
                                                    hn::Mul(hn::Set(df, 4.0f), hn::Mul(det, det))),
                                            zero))));
    const auto above = hn::Gt(major2, one);
    const V log2 = sv::core::HWY_NAMESPACE::Log2Positive(df, hn::IfThenElse(above, major2, one));
    const V lod = hn::Min(hn::Mul(half, log2), hn::Set(df, 63.0f));
    hn::Store(hn::IfThenElseZero(above, lod), df, tc.lod + i);
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::terrain
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sv::terrain {
HWY_EXPORT(ShadeLanesKernel);

void shadeLanes(const ShadeFrame& frame, const ShadeLanes& lanes, shade::Fragments& frag,
                shade::TexCoords& tc) {
  HWY_DYNAMIC_DISPATCH(ShadeLanesKernel)(frame, lanes, frag, tc);
}

}  // namespace sv::terrain
#endif  // HWY_ONCE
