// Pixel shading in SIMD lanes, one lane per pixel (Highway, dispatched per call).
//
// Symbols (shading.h): q = 1/w; an attribute plane holds a/w, so a = (a/w)·w. Texture coordinates
// to level-0 texels: x₀ = u·width − ½ (texture.h). The footprint's Jacobian (footprint.h):
//     ∂u/∂x = (U_x − u·q_x)·w·width   (and alike for y and v),
// its larger singular value σ₁ from S = a² + b² + c² + d², D = ad − bc:
//     σ₁² = (S + √(S² − 4D²)) / 2,   level of detail = max(0, ½·log2 σ₁²).
// Phong (SPEC §8, seed 003): C = (Q_amb·C_surf + Q_diff·C_surf·Σ(n·l)⁺C_light +
// Q_spec·Σ((r·v)⁺)^p·C_light) / (Q_amb + Q_diff + Q_spec). Fog (seed 002): C·f + C_F·(1 − f), f =
// 2^(−β·|eye position|). Only multiplies, adds, divisions and square roots (all exactly rounded):
// the same bits on every SIMD target (tests/shade/shade_test.cpp).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "shade/shade_fragments.cpp"
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include "core/check.h"
#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"
#include "shade/shading.h"
#include "texture/footprint.h"
#include "texture/sample_block-inl.h"

HWY_BEFORE_NAMESPACE();
namespace sv::shade {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using DF = hn::CappedTag<float, kMaxFragments>;
using VF = hn::Vec<DF>;

struct V3 {
  VF x, y, z;
};

// log2 and exp2 of our own, from multiplies, adds, one division and exponent bits only — no
// fused multiply-add, which some targets have and others not — so that every SIMD target shades
// every pixel to the same bits (docs/ARCHITECTURE.md, invariants).
// log2(x), x > 0 normal: x = 2^e·m, m ∈ [1, 2); log2 m = (2/ln 2)·atanh t, t = (m − 1)/(m + 1)
// ∈ [0, 1/3), by its series to t⁹ (error < 3·10⁻⁷).
HWY_INLINE VF log2(DF df, VF x) {
  const hn::RebindToSigned<DF> di;
  const auto bits = hn::BitCast(di, x);
  const VF e = hn::ConvertTo(df, hn::Sub(hn::ShiftRight<23>(bits), hn::Set(di, 127)));
  const VF m =
      hn::BitCast(df, hn::Or(hn::And(bits, hn::Set(di, 0x7FFFFF)), hn::Set(di, 0x3F800000)));
  const VF one = hn::Set(df, 1.0f);
  const VF t = hn::Div(hn::Sub(m, one), hn::Add(m, one));
  const VF t2 = hn::Mul(t, t);
  VF p = hn::Set(df, 1.0f / 9);
  for (float c : {1.0f / 7, 1.0f / 5, 1.0f / 3, 1.0f}) p = hn::Add(hn::Mul(p, t2), hn::Set(df, c));
  return hn::Add(e, hn::Mul(hn::Mul(p, t), hn::Set(df, 2.8853900817779268f)));  // 2/ln 2
}

// exp2(y) for y ≤ 0 (fog, and specular powers of numbers ≤ 1): 2^n·2^f, n = ⌊y⌋, f ∈ [0, 1),
// 2^f by e^(f·ln 2)'s series to the 8th power (error < 2·10⁻⁷); 0 below 2^−126.
HWY_INLINE VF exp2(DF df, VF y) {
  const hn::RebindToSigned<DF> di;
  y = hn::Max(y, hn::Set(df, -127.0f));
  const VF n = hn::Floor(y);
  const VF g = hn::Mul(hn::Sub(y, n), hn::Set(df, 0.69314718055994531f));
  VF p = hn::Set(df, 1.0f / 40320);
  for (float c : {1.0f / 5040, 1.0f / 720, 1.0f / 120, 1.0f / 24, 1.0f / 6, 0.5f, 1.0f, 1.0f})
    p = hn::Add(hn::Mul(p, g), hn::Set(df, c));
  const auto ni = hn::ConvertTo(di, n);
  const VF scale = hn::BitCast(df, hn::ShiftLeft<23>(hn::Add(ni, hn::Set(di, 127))));
  return hn::IfThenElseZero(hn::Gt(n, hn::Set(df, -127.0f)), hn::Mul(p, scale));
}

HWY_INLINE VF dot3(const V3& a, const V3& b) {
  return hn::Add(hn::Add(hn::Mul(a.x, b.x), hn::Mul(a.y, b.y)), hn::Mul(a.z, b.z));
}

HWY_INLINE V3 normalized(DF df, const V3& a) {
  const VF len2 = dot3(a, a);
  // A zero vector stays zero (its lighting terms vanish) rather than becoming NaN.
  const VF inv = hn::IfThenElseZero(hn::Gt(len2, hn::Set(df, 1e-30f)),
                                    hn::Div(hn::Set(df, 1.0f), hn::Sqrt(len2)));
  return {hn::Mul(a.x, inv), hn::Mul(a.y, inv), hn::Mul(a.z, inv)};
}

// Adds one light's diffuse (n·l)⁺·C and specular ((r·v)^p)·C terms; l and v unit, toward the light
// and the eye.
HWY_INLINE void addLight(DF df, const MaterialShading& m, const V3& n, const V3& l, const V3& v,
                         Vec3 color, V3& diffuse, V3& specular) {
  const VF nl = dot3(n, l);
  const VF d = hn::Max(nl, hn::Zero(df));
  diffuse.x = hn::Add(diffuse.x, hn::Mul(d, hn::Set(df, color.x)));
  diffuse.y = hn::Add(diffuse.y, hn::Mul(d, hn::Set(df, color.y)));
  diffuse.z = hn::Add(diffuse.z, hn::Mul(d, hn::Set(df, color.z)));
  if (m.specular <= 0) return;
  // r = 2(n·l)n − l; only lit sides reflect.
  const VF two = hn::Add(nl, nl);
  const V3 r{hn::Sub(hn::Mul(two, n.x), l.x), hn::Sub(hn::Mul(two, n.y), l.y),
             hn::Sub(hn::Mul(two, n.z), l.z)};
  const VF rv = hn::IfThenElseZero(hn::Gt(nl, hn::Zero(df)), hn::Max(dot3(r, v), hn::Zero(df)));
  // (r·v)^p = e^(p·ln(r·v)); 0 stays 0.
  const VF s = hn::IfThenElseZero(
      hn::Gt(rv, hn::Zero(df)),
      exp2(df, hn::Mul(hn::Set(df, m.shininess), log2(df, hn::Max(rv, hn::Set(df, 1e-30f))))));
  specular.x = hn::Add(specular.x, hn::Mul(s, hn::Set(df, color.x)));
  specular.y = hn::Add(specular.y, hn::Mul(s, hn::Set(df, color.y)));
  specular.z = hn::Add(specular.z, hn::Mul(s, hn::Set(df, color.z)));
}

// Texture coordinates (level-0 texels) and levels of detail of every lane (shading.h).
void TextureCoordinates(const MaterialShading& m, const Fragments& f, TexCoords& out,
                        bool prefetch) {
  if (!m.texture) return;
  const DF df;
  const size_t lanes = hn::Lanes(df);
  const VF one = hn::Set(df, 1.0f), zero = hn::Zero(df);
  const float width = float(m.texture->level(0).width), height = float(m.texture->level(0).height);
  // The block's bounding box in level-0 texels, for the prefetch (the anisotropic sampler's probes
  // lie elsewhere: none); only the fragments there are, insane coordinates left out.
  const bool box = prefetch && !m.anisotropic;
  const size_t live = size_t(std::clamp(f.count, 0, kMaxFragments));
  const VF big = hn::Set(df, texture::kMaxTexelCoordinate);
  VF xMin = big, yMin = big, xMax = hn::Neg(big), yMax = hn::Neg(big);
  float major0 = 0;  // the first lane's σ₁², for the prefetch
  for (size_t i = 0; i < size_t(kMaxFragments); i += lanes) {
    // Outside the triangle (extrapolated AA centroids) q may reach 0: keep w finite.
    const VF q = hn::Max(hn::Load(df, f.q + i), hn::Set(df, 1e-30f));
    const VF w = hn::Div(one, q);
    const VF u = hn::Mul(hn::Load(df, f.attribute[kU] + i), w);
    const VF v = hn::Mul(hn::Load(df, f.attribute[kV] + i), w);
    const VF x0 = hn::Sub(hn::Mul(u, hn::Set(df, width)), hn::Set(df, 0.5f));
    const VF y0 = hn::Sub(hn::Mul(v, hn::Set(df, height)), hn::Set(df, 0.5f));
    hn::Store(x0, df, out.x0 + i);
    hn::Store(y0, df, out.y0 + i);
    if (box) {
      const auto sane = hn::And(hn::FirstN(df, live > i ? live - i : 0),
                                hn::And(hn::Le(hn::Abs(x0), big), hn::Le(hn::Abs(y0), big)));
      xMin = hn::Min(xMin, hn::IfThenElse(sane, x0, big));
      yMin = hn::Min(yMin, hn::IfThenElse(sane, y0, big));
      xMax = hn::Max(xMax, hn::IfThenElse(sane, x0, hn::Neg(big)));
      yMax = hn::Max(yMax, hn::IfThenElse(sane, y0, hn::Neg(big)));
    }
    const VF ww = hn::Mul(w, hn::Set(df, width)), wh = hn::Mul(w, hn::Set(df, height));
    const VF a = hn::Mul(hn::Sub(hn::Set(df, f.udx), hn::Mul(u, hn::Set(df, f.qdx))), ww);
    const VF b = hn::Mul(hn::Sub(hn::Set(df, f.udy), hn::Mul(u, hn::Set(df, f.qdy))), ww);
    const VF c = hn::Mul(hn::Sub(hn::Set(df, f.vdx), hn::Mul(v, hn::Set(df, f.qdx))), wh);
    const VF d = hn::Mul(hn::Sub(hn::Set(df, f.vdy), hn::Mul(v, hn::Set(df, f.qdy))), wh);
    const VF s =
        hn::Add(hn::Add(hn::Mul(a, a), hn::Mul(b, b)), hn::Add(hn::Mul(c, c), hn::Mul(d, d)));
    const VF det = hn::Sub(hn::Mul(a, d), hn::Mul(b, c));
    const VF disc =
        hn::Max(hn::Sub(hn::Mul(s, s), hn::Mul(hn::Set(df, 4.0f), hn::Mul(det, det))), zero);
    const VF major2 = hn::Mul(hn::Add(s, hn::Sqrt(disc)), hn::Set(df, 0.5f));
    if (i == 0) major0 = hn::GetLane(major2);
    // ½·log2(σ₁²), at least 0; a degenerate or non-finite footprint reads level 0.
    VF l = hn::Mul(log2(df, hn::Max(major2, one)), hn::Set(df, 0.5f));
    l = hn::IfThenElseZero(hn::Lt(l, hn::Set(df, 64.0f)), l);  // also false for NaN
    if (m.levelZero) l = zero;
    hn::Store(l, df, out.lod + i);
  }
  // The texels the samplers will read, requested now (the caller shades a queue's work later):
  // on the level the first lane reads, found from the exponent of its σ₁² (½·log2 σ₁² rounded
  // down, or to nearest for the single-level filters) rather than from its level of detail, whose
  // logarithm the request would otherwise wait for. Near a level's edge the two may differ by
  // one, which costs the request its use but changes nothing else.
  if (box) {
    const int e = major0 >= 1.0f && std::isfinite(major0)
                      ? int(std::bit_cast<uint32_t>(major0) >> 23) - 127
                      : 0;
    const bool trilinear =
        m.filter == texture::Filter::trilinear || m.filter == texture::Filter::trilinearThreePoint;
    const int k = m.levelZero ? 0 : (e + (trilinear ? 0 : 1)) >> 1;
    texture::HWY_NAMESPACE::BlockSampler(*m.texture)
        .prefetch(k, trilinear && !m.levelZero, hn::GetLane(hn::MinOfLanes(df, xMin)),
                  hn::GetLane(hn::MaxOfLanes(df, xMax)), hn::GetLane(hn::MinOfLanes(df, yMin)),
                  hn::GetLane(hn::MaxOfLanes(df, yMax)));
  }
}

void ShadeFragments(const MaterialShading& m, const Environment& env, const Fragments& f,
                    const TexCoords* given, float out[4][kMaxFragments]) {
  const DF df;
  const size_t lanes = hn::Lanes(df);
  const VF one = hn::Set(df, 1.0f), zero = hn::Zero(df);
  alignas(64) float texel[4][kMaxFragments];
  const int count = std::clamp(f.count, 0, kMaxFragments);
  TexCoords computed;
  if (m.texture && !given) TextureCoordinates(m, f, computed, false);
  const TexCoords& tc = given ? *given : computed;
  const bool opaqueTexture = m.texture && m.texture->opaque();
  if (m.texture && m.anisotropic) {
    // The elliptical footprint per pixel (footprint.h), probes along its major axis.
    const float width = float(m.texture->level(0).width);
    texture::Footprint fp[kMaxFragments];
    for (int i = 0; i < count; ++i) {
      const double q = std::max(double(f.q[i]), 1e-30);
      fp[i] = texture::pixelFootprint({double(f.attribute[kU][i]), f.udx, f.udy},
                                      {double(f.attribute[kV][i]), f.vdx, f.vdy}, {q, f.qdx, f.qdy},
                                      width, m.texture->level(0).height);
    }
    texture::anisotropicBlock(*m.texture, fp, tc.x0, tc.y0, count, texel);
  }
  for (size_t i = 0; i < size_t(kMaxFragments); i += lanes) {
    const VF q = hn::Max(hn::Load(df, f.q + i), hn::Set(df, 1e-30f));
    const VF w = hn::Div(one, q);
    V3 c{hn::Load(df, f.color[0] + i), hn::Load(df, f.color[1] + i), hn::Load(df, f.color[2] + i)};
    // (Fragments holds only the attributes attributesUsed names.)
    VF alpha = m.alpha == AlphaUse::opaque
                   ? one
                   : hn::Min(hn::Max(hn::Mul(hn::Load(df, f.attribute[kAlpha] + i), w), zero), one);
    if (m.texture) {
      // The block sampler runs here, in this target's lanes (sample_block-inl.h).
      const texture::HWY_NAMESPACE::Lanes4 t =
          m.anisotropic ? texture::HWY_NAMESPACE::Lanes4{hn::Load(df, texel[0] + i),
                                                         hn::Load(df, texel[1] + i),
                                                         hn::Load(df, texel[2] + i),
                                                         hn::Load(df, texel[3] + i)}
                        : texture::HWY_NAMESPACE::BlockSampler(*m.texture)
                              .sample(m.filter, hn::Load(df, tc.lod + i), hn::Load(df, tc.x0 + i),
                                      hn::Load(df, tc.y0 + i));
      if (opaqueTexture) {
        // Alpha exactly 1 (Texture::opaque): nothing to divide or multiply by.
        c.x = hn::Mul(c.x, t.r);
        c.y = hn::Mul(c.y, t.g);
        c.z = hn::Mul(c.z, t.b);
      } else {
        // Texels are premultiplied; the surface colour is the straight one (0 where alpha is 0).
        const VF inv = hn::IfThenElseZero(hn::Gt(t.a, zero), hn::Div(one, t.a));
        c.x = hn::Mul(c.x, hn::Mul(t.r, inv));
        c.y = hn::Mul(c.y, hn::Mul(t.g, inv));
        c.z = hn::Mul(c.z, hn::Mul(t.b, inv));
        alpha = hn::Mul(alpha, t.a);
      }
    }
    V3 eye{zero, zero, zero};
    if (m.phong || env.fog)
      eye = {hn::Mul(hn::Load(df, f.attribute[kEyeX] + i), w),
             hn::Mul(hn::Load(df, f.attribute[kEyeY] + i), w),
             hn::Mul(hn::Load(df, f.attribute[kEyeZ] + i), w)};
    if (m.phong) {
      // n/w interpolated: its direction is n's, so it needs no division by q.
      V3 n = normalized(
          df, {hn::Load(df, f.attribute[kNormalX] + i), hn::Load(df, f.attribute[kNormalY] + i),
               hn::Load(df, f.attribute[kNormalZ] + i)});
      const V3 view = normalized(df, {hn::Neg(eye.x), hn::Neg(eye.y), hn::Neg(eye.z)});
      if (m.twoSided) {
        const auto back = hn::Lt(dot3(n, view), zero);
        n = {hn::IfThenElse(back, hn::Neg(n.x), n.x), hn::IfThenElse(back, hn::Neg(n.y), n.y),
             hn::IfThenElse(back, hn::Neg(n.z), n.z)};
      }
      V3 diffuse{zero, zero, zero}, specular{zero, zero, zero};
      if (env.lightOn) {
        const V3 l{hn::Set(df, env.toLight.x), hn::Set(df, env.toLight.y),
                   hn::Set(df, env.toLight.z)};
        addLight(df, m, n, l, view, env.lightColor, diffuse, specular);
      }
      for (const PointLightEye& p : env.points) {
        const V3 l = normalized(df, {hn::Sub(hn::Set(df, p.position.x), eye.x),
                                     hn::Sub(hn::Set(df, p.position.y), eye.y),
                                     hn::Sub(hn::Set(df, p.position.z), eye.z)});
        addLight(df, m, n, l, view, p.color, diffuse, specular);
      }
      const float qAmb = env.ambient, qDiff = 1 - env.ambient, qSpec = m.specular;
      const VF norm = hn::Set(df, 1.0f / (qAmb + qDiff + qSpec));
      auto light = [&](VF surf, VF dif, VF spec) {
        const VF sum =
            hn::Add(hn::Mul(hn::Set(df, qSpec), spec),
                    hn::Mul(surf, hn::Add(hn::Mul(hn::Set(df, qDiff), dif), hn::Set(df, qAmb))));
        return hn::Mul(sum, norm);
      };
      c = {light(c.x, diffuse.x, specular.x), light(c.y, diffuse.y, specular.y),
           light(c.z, diffuse.z, specular.z)};
    }
    if (m.alpha == AlphaUse::opaque) alpha = one;
    if (m.alpha == AlphaUse::mask)
      alpha = hn::IfThenElseZero(hn::Ge(alpha, hn::Set(df, m.alphaCutoff)), one);
    if (env.fog) {
      // SPEC §8: f = 2^(−β·r) = e^(−β·ln2·r), r the true range |eye position|.
      const VF range = hn::Sqrt(dot3(eye, eye));
      const VF fog = exp2(df, hn::Mul(hn::Set(df, -env.fogBeta), range));
      const VF haze = hn::Sub(one, fog);
      c.x = hn::Add(hn::Mul(c.x, fog), hn::Mul(hn::Set(df, env.fogColor.x), haze));
      c.y = hn::Add(hn::Mul(c.y, fog), hn::Mul(hn::Set(df, env.fogColor.y), haze));
      c.z = hn::Add(hn::Mul(c.z, fog), hn::Mul(hn::Set(df, env.fogColor.z), haze));
    }
    // Premultiplied, clamped to the 0…1 the frame buffer stores.
    hn::Store(hn::Min(hn::Max(hn::Mul(c.x, alpha), zero), one), df, out[0] + i);
    hn::Store(hn::Min(hn::Max(hn::Mul(c.y, alpha), zero), one), df, out[1] + i);
    hn::Store(hn::Min(hn::Max(hn::Mul(c.z, alpha), zero), one), df, out[2] + i);
    hn::Store(alpha, df, out[3] + i);
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::shade
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sv::shade {
HWY_EXPORT(ShadeFragments);
HWY_EXPORT(TextureCoordinates);

void shadeFragments(const MaterialShading& m, const Environment& env, const Fragments& f,
                    float out[4][kMaxFragments]) {
  SV_DCHECK(reinterpret_cast<uintptr_t>(out) % 64 == 0);
  HWY_DYNAMIC_DISPATCH(ShadeFragments)(m, env, f, nullptr, out);
}

void textureCoordinates(const MaterialShading& m, const Fragments& f, TexCoords& out,
                        bool request) {
  HWY_DYNAMIC_DISPATCH(TextureCoordinates)(m, f, out, request);
}

void shadeFragments(const MaterialShading& m, const Environment& env, const Fragments& f,
                    const TexCoords& coordinates, float out[4][kMaxFragments]) {
  SV_DCHECK(reinterpret_cast<uintptr_t>(out) % 64 == 0);
  HWY_DYNAMIC_DISPATCH(ShadeFragments)(m, env, f, &coordinates, out);
}
}  // namespace sv::shade
#endif
