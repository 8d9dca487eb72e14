// classifySamples (sample_kernel.h): trilinear codes from 32-bit gathers (a cell's two samples
// along x are adjacent 16-bit codes, so four gathers read its eight corners; in the bordered 8-bit
// codes one read holds a row's four), the transfer
// function's table read linearly, the step-corrected opacity, the gradient (precomputed per sample
// or by central differences) and its two-sided Phong weighting, in lanes.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "volume/sample_kernel.cpp"
// clang-format off: foreach_target.h first
#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"
// clang-format on

#include <algorithm>

#include "core/lane_math-inl.h"
#include "volume/sample_kernel.h"

HWY_BEFORE_NAMESPACE();
namespace sv::volume {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using DF = hn::ScalableTag<float>;
using DI = hn::RebindToSigned<DF>;
using DU = hn::RebindToUnsigned<DF>;
using VF = hn::Vec<DF>;
using VI = hn::Vec<DI>;

HWY_INLINE VF Lerp(VF a, VF b, VF t) { return hn::Add(a, hn::Mul(t, hn::Sub(b, a))); }

// A point's cell: its first sample's index and the point's place in it (clamped to the grid, as
// the scalar Sampler::locate).
struct Cell {
  VI base;
  VI padded;  // byte offset of the cell's first sample in the bordered codes read (8- or 16-bit)
  VF tx, ty, tz;
};

HWY_INLINE Cell Locate(const SampleSource& s, VF x, VF y, VF z) {
  const DF df;
  const DI di;
  const VF zero = hn::Zero(df);
  const VF fx = hn::Min(hn::Max(hn::Mul(x, hn::Set(df, s.inverseSpacing[0])), zero),
                        hn::Set(df, float(s.nx - 1)));
  const VF fy = hn::Min(hn::Max(hn::Mul(y, hn::Set(df, s.inverseSpacing[1])), zero),
                        hn::Set(df, float(s.ny - 1)));
  const VF fz = hn::Min(hn::Max(hn::Mul(z, hn::Set(df, s.inverseSpacing[2])), zero),
                        hn::Set(df, float(s.nz - 1)));
  const VI i = hn::Min(hn::ConvertTo(di, fx), hn::Set(di, s.nx - 2));
  const VI j = hn::Min(hn::ConvertTo(di, fy), hn::Set(di, s.ny - 2));
  const VI k = hn::Min(hn::ConvertTo(di, fz), hn::Set(di, s.nz - 2));
  Cell c;
  c.base = hn::Add(hn::Mul(hn::Add(hn::Mul(k, hn::Set(di, s.ny)), j), hn::Set(di, s.nx)), i);
  if (s.padded8 || s.padded) {
    const VI one = hn::Set(di, 1);
    const VI at = hn::Add(hn::Mul(hn::Add(hn::Mul(hn::Add(k, one), hn::Set(di, s.ny + 2)),
                                          hn::Add(j, one)),
                                  hn::Set(di, s.nx + 2)),
                          hn::Add(i, one));
    c.padded = s.padded8 ? at : hn::Add(at, at);
  } else {
    c.padded = hn::Zero(di);
  }
  c.tx = hn::Sub(fx, hn::ConvertTo(df, i));
  c.ty = hn::Sub(fy, hn::ConvertTo(df, j));
  c.tz = hn::Sub(fz, hn::ConvertTo(df, k));
  return c;
}

// The trilinear code over cell `c`: a 32-bit read at a sample holds it (low half) and its x
// neighbour (high half).
HWY_INLINE VF Codes(const SampleSource& s, const Cell& c) {
  const DF df;
  const DI di;
  const DU du;
  const auto* base = reinterpret_cast<const int32_t*>(s.codes);
  const VI bytes = hn::Add(c.base, c.base);
  const VI sy = hn::Set(di, 2 * s.nx), sz = hn::Set(di, 2 * s.nx * s.ny);
  const VI mask = hn::Set(di, 0xFFFF);
  auto pair = [&](VI offset, VF& lo, VF& hi) {
    const VI v = hn::GatherOffset(di, base, offset);
    lo = hn::ConvertTo(df, hn::And(v, mask));
    hi = hn::ConvertTo(df, hn::BitCast(di, hn::ShiftRight<16>(hn::BitCast(du, v))));
  };
  VF v000, v100, v010, v110, v001, v101, v011, v111;
  pair(bytes, v000, v100);
  pair(hn::Add(bytes, sy), v010, v110);
  pair(hn::Add(bytes, sz), v001, v101);
  pair(hn::Add(hn::Add(bytes, sz), sy), v011, v111);
  const VF c00 = Lerp(v000, v100, c.tx), c10 = Lerp(v010, v110, c.tx);
  const VF c01 = Lerp(v001, v101, c.tx), c11 = Lerp(v011, v111, c.tx);
  return Lerp(Lerp(c00, c10, c.ty), Lerp(c01, c11, c.ty), c.tz);
}

HWY_INLINE VF CodesAt(const SampleSource& s, VF x, VF y, VF z) {
  return Codes(s, Locate(s, x, y, z));
}

// The precomputed gradient directions over cell `c`, trilinear per axis.
HWY_INLINE void Normals(const SampleSource& s, const Cell& c, VF g[3]) {
  const DF df;
  const DI di;
  const auto* base = reinterpret_cast<const int32_t*>(s.normals);
  const VI one = hn::Set(di, 1), sy = hn::Set(di, s.nx), sz = hn::Set(di, s.nx * s.ny);
  const VI at[8] = {c.base,
                    hn::Add(c.base, one),
                    hn::Add(c.base, sy),
                    hn::Add(hn::Add(c.base, sy), one),
                    hn::Add(c.base, sz),
                    hn::Add(hn::Add(c.base, sz), one),
                    hn::Add(hn::Add(c.base, sz), sy),
                    hn::Add(hn::Add(hn::Add(c.base, sz), sy), one)};
  VF corner[3][8];
  for (int n = 0; n < 8; ++n) {
    const VI v = hn::GatherIndex(di, base, at[n]);
    // The bytes x, y, z (little-endian), sign-extended.
    corner[0][n] = hn::ConvertTo(df, hn::ShiftRight<24>(hn::ShiftLeft<24>(v)));
    corner[1][n] = hn::ConvertTo(df, hn::ShiftRight<24>(hn::ShiftLeft<16>(v)));
    corner[2][n] = hn::ConvertTo(df, hn::ShiftRight<24>(hn::ShiftLeft<8>(v)));
  }
  for (int a = 0; a < 3; ++a) {
    const VF* v = corner[a];
    const VF c00 = Lerp(v[0], v[1], c.tx), c10 = Lerp(v[2], v[3], c.tx);
    const VF c01 = Lerp(v[4], v[5], c.tx), c11 = Lerp(v[6], v[7], c.tx);
    g[a] = Lerp(Lerp(c00, c10, c.ty), Lerp(c01, c11, c.ty), c.tz);
  }
}

// The rows of the cross of cells about a sample's cell in the bordered codes: along x, the codes at
// x = i − 1 … i + 2 of the rows y ∈ {j, j + 1}, z ∈ {k, k + 1} — the cell and its neighbours before
// and after along x.
struct CrossRows {
  VF x[2][2][4];  // [dz][dy][x − i + 1]
};

// Byte offset in the bordered codes of (i + 1 + dx, j + 1 + dy, k + 1 + dz) — the cell's own
// sample (i, j, k) moved by (dx, dy, dz) — for codes of T.
template <typename T>
HWY_INLINE VI CrossAt(const SampleSource& s, const Cell& c, int dx, int dy, int dz) {
  const DI di;
  const int px = s.nx + 2, pxy = (s.nx + 2) * (s.ny + 2);
  return hn::Add(c.padded, hn::Set(di, int(sizeof(T)) * (dx + dy * px + dz * pxy)));
}

// The codes at a point and its x neighbour from one 32-bit read at its byte offset.
HWY_INLINE void PairAt(const uint16_t* codes, VI offset, VF& lo, VF& hi) {
  const DF df;
  const DI di;
  const DU du;
  const VI v = hn::GatherOffset(di, reinterpret_cast<const int32_t*>(codes), offset);
  lo = hn::ConvertTo(df, hn::And(v, hn::Set(di, 0xFFFF)));
  hi = hn::ConvertTo(df, hn::BitCast(di, hn::ShiftRight<16>(hn::BitCast(du, v))));
}
HWY_INLINE void PairAt(const uint8_t* codes, VI offset, VF& lo, VF& hi) {
  const DF df;
  const DI di;
  const VI v = hn::GatherOffset(di, reinterpret_cast<const int32_t*>(codes), offset);
  const VI mask = hn::Set(di, 0xFF);
  lo = hn::ConvertTo(df, hn::And(v, mask));
  hi = hn::ConvertTo(df, hn::And(hn::ShiftRight<8>(v), mask));
}

// The four codes of a cross row, x = i − 1 … i + 2: two pair reads of 16-bit codes, one read of
// 8-bit ones.
HWY_INLINE void RowAt(const SampleSource& s, const uint16_t* codes, const Cell& c, int dy, int dz,
                      VF row[4]) {
  PairAt(codes, CrossAt<uint16_t>(s, c, -1, dy, dz), row[0], row[1]);
  PairAt(codes, CrossAt<uint16_t>(s, c, 1, dy, dz), row[2], row[3]);
}
HWY_INLINE void RowAt(const SampleSource& s, const uint8_t* codes, const Cell& c, int dy, int dz,
                      VF row[4]) {
  const DF df;
  const DI di;
  const DU du;
  const VI v = hn::GatherOffset(di, reinterpret_cast<const int32_t*>(codes),
                                CrossAt<uint8_t>(s, c, -1, dy, dz));
  const VI mask = hn::Set(di, 0xFF);
  row[0] = hn::ConvertTo(df, hn::And(v, mask));
  row[1] = hn::ConvertTo(df, hn::And(hn::ShiftRight<8>(v), mask));
  row[2] = hn::ConvertTo(df, hn::And(hn::ShiftRight<16>(v), mask));
  row[3] = hn::ConvertTo(df, hn::BitCast(di, hn::ShiftRight<24>(hn::BitCast(du, v))));
}

// Trilinear over the cell whose x-lerped rows are r00 (y0 z0), r10 (y1 z0), r01, r11.
HWY_INLINE VF Blend(const Cell& c, VF r00, VF r10, VF r01, VF r11) {
  return Lerp(Lerp(r00, r10, c.ty), Lerp(r01, r11, c.ty), c.tz);
}

// The value over cell `c` from the cross's x rows (read into `rows`).
template <typename T>
HWY_INLINE VF CrossValue(const SampleSource& s, const T* codes, const Cell& c, CrossRows& rows) {
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy) RowAt(s, codes, c, dy, dz, rows.x[dz][dy]);
  VF mid[2][2];
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy) mid[dz][dy] = Lerp(rows.x[dz][dy][1], rows.x[dz][dy][2], c.tx);
  return Blend(c, mid[0][0], mid[0][1], mid[1][0], mid[1][1]);
}

// The central differences about cell `c` (the values over the cells one sample before and after it
// along each axis, same weights): x from the cross's x rows, y and z from its other eight rows
// (y ∈ {j − 1, j + 2} with z ∈ {k, k + 1}, z ∈ {k − 1, k + 2} with y ∈ {j, j + 1}; x i, i + 1).
template <typename T>
HWY_INLINE void CrossGradient(const SampleSource& s, const T* codes, const Cell& c,
                              const CrossRows& cross, VF g[3]) {
  const DF df;
  VF y[2][2][2], z[2][2][2];  // [dz or dy][before/after][x]
  for (int d = 0; d < 2; ++d) {
    PairAt(codes, CrossAt<T>(s, c, 0, -1, d), y[d][0][0], y[d][0][1]);
    PairAt(codes, CrossAt<T>(s, c, 0, 2, d), y[d][1][0], y[d][1][1]);
    PairAt(codes, CrossAt<T>(s, c, 0, d, -1), z[d][0][0], z[d][0][1]);
    PairAt(codes, CrossAt<T>(s, c, 0, d, 2), z[d][1][0], z[d][1][1]);
  }
  VF rows[2][2][3];  // x-lerped rows at x offsets −1, 0, +1 (cells i − 1, i, i + 1)
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int o = 0; o < 3; ++o)
        rows[dz][dy][o] = Lerp(cross.x[dz][dy][o], cross.x[dz][dy][o + 1], c.tx);
  const VF xm = Blend(c, rows[0][0][0], rows[0][1][0], rows[1][0][0], rows[1][1][0]);
  const VF xp = Blend(c, rows[0][0][2], rows[0][1][2], rows[1][0][2], rows[1][1][2]);
  // The cells one before and after along y: rows (y − 1, y) and (y + 1, y + 2).
  const VF yBefore[2] = {Lerp(y[0][0][0], y[0][0][1], c.tx), Lerp(y[1][0][0], y[1][0][1], c.tx)};
  const VF yAfter[2] = {Lerp(y[0][1][0], y[0][1][1], c.tx), Lerp(y[1][1][0], y[1][1][1], c.tx)};
  const VF ym = Blend(c, yBefore[0], rows[0][0][1], yBefore[1], rows[1][0][1]);
  const VF yp = Blend(c, rows[0][1][1], yAfter[0], rows[1][1][1], yAfter[1]);
  const VF zBefore[2] = {Lerp(z[0][0][0], z[0][0][1], c.tx), Lerp(z[1][0][0], z[1][0][1], c.tx)};
  const VF zAfter[2] = {Lerp(z[0][1][0], z[0][1][1], c.tx), Lerp(z[1][1][0], z[1][1][1], c.tx)};
  const VF zm = Blend(c, zBefore[0], zBefore[1], rows[0][0][1], rows[0][1][1]);
  const VF zp = Blend(c, rows[1][0][1], rows[1][1][1], zAfter[0], zAfter[1]);
  const VF two = hn::Set(df, 2.0f);
  g[0] = hn::Div(hn::Sub(xp, xm), hn::Mul(two, hn::Set(df, s.spacing[0])));
  g[1] = hn::Div(hn::Sub(yp, ym), hn::Mul(two, hn::Set(df, s.spacing[1])));
  g[2] = hn::Div(hn::Sub(zp, zm), hn::Mul(two, hn::Set(df, s.spacing[2])));
}

void ClassifySamples(const SampleSource& s, int count, SampleBatch& b) {
  const DF df;
  const DI di;
  const size_t n = hn::Lanes(df);
  const float* table = s.table;
  const VI last = hn::Set(di, std::max(s.entries - 2, 0));
  const bool two = s.entries > 1;
  for (size_t i = 0; i < size_t(count); i += n) {
    const VF x = hn::Load(df, b.x + i), y = hn::Load(df, b.y + i), z = hn::Load(df, b.z + i);
    const Cell cell = Locate(s, x, y, z);
    VF g[3];
    // The value from the bordered codes' cross where they are kept: the 8-bit ones lit or not
    // (one 32-bit gather a row of four codes), the 16-bit ones for the gradient's sake.
    const bool crossed = !s.normals && (s.padded8 || (s.shade && s.padded));
    CrossRows cross;
    const VF code = !crossed  ? Codes(s, cell)
                    : s.padded8 ? CrossValue(s, s.padded8, cell, cross)
                                : CrossValue(s, s.padded, cell, cross);
    // SPEC §11: the transfer function's table read linearly between the entries about the code.
    const VF pos = hn::Mul(code, hn::Set(df, s.codeScale));
    const VI e = hn::Min(hn::ConvertTo(di, pos), last);
    const VF f = two ? hn::Sub(pos, hn::ConvertTo(df, e)) : hn::Zero(df);
    const VI e4 = hn::ShiftLeft<2>(e);
    const VI next = two ? hn::Add(e4, hn::Set(di, 4)) : e4;
    VF channel[4];
    for (int ch = 0; ch < 4; ++ch) {
      const VF t0 = hn::GatherIndex(df, table + ch, e4), t1 = hn::GatherIndex(df, table + ch, next);
      channel[ch] = Lerp(t0, t1, f);
    }
    hn::Store(channel[3], df, b.opacity + i);
    if (s.stepOpacity) {
      // SPEC §12: the opacity of a full step, 1 − (1 − W)^(l / unit), tabled per entry.
      const VF c0 = hn::GatherIndex(df, s.stepOpacity, e);
      const VF c1 = two ? hn::GatherIndex(df, s.stepOpacity, hn::Add(e, hn::Set(di, 1))) : c0;
      hn::Store(Lerp(c0, c1, f), df, b.w + i);
    } else if (b.exponent > 0) {
      // The same for the ray's own step: (1 − W)^e = 2^(e·log2(1 − W)); W ≥ 1 stays opaque.
      const VF one = hn::Set(df, 1.0f);
      const VF clear = hn::Sub(one, hn::Min(channel[3], one));
      const auto opaque = hn::Not(hn::Gt(clear, hn::Set(df, 1e-30f)));
      const VF left = sv::core::HWY_NAMESPACE::Exp2(
          df, hn::Mul(hn::Set(df, b.exponent), sv::core::HWY_NAMESPACE::Log2Positive(
                                                   df, hn::IfThenElse(opaque, one, clear))));
      hn::Store(hn::IfThenElse(opaque, one, hn::Sub(one, left)), df, b.w + i);
    }
    // Transparent samples are not composited: their colour is zero, and where the whole vector is
    // transparent neither the gradient nor the weighting is taken (the same bits in every lane
    // whatever the vector's width).
    const auto transparent = hn::Not(hn::Gt(channel[3], hn::Zero(df)));
    if (s.shade && !hn::AllTrue(df, transparent)) {
      if (s.normals) {
        Normals(s, cell, g);
      } else if (crossed) {
        if (s.padded8) CrossGradient(s, s.padded8, cell, cross, g);
        else CrossGradient(s, s.padded, cell, cross, g);
      } else {
        // Central differences of the interpolated value over one sample spacing each way.
        const VF h[3] = {hn::Set(df, s.spacing[0]), hn::Set(df, s.spacing[1]),
                         hn::Set(df, s.spacing[2])};
        const VF p[3] = {x, y, z};
        for (int a = 0; a < 3; ++a) {
          VF up[3] = {p[0], p[1], p[2]}, down[3] = {p[0], p[1], p[2]};
          up[a] = hn::Add(p[a], h[a]);
          down[a] = hn::Sub(p[a], h[a]);
          g[a] = hn::Div(hn::Sub(CodesAt(s, up[0], up[1], up[2]), CodesAt(s, down[0], down[1], down[2])),
                         hn::Add(h[a], h[a]));
        }
      }
      // To the world by the inverse transpose; two-sided (a volume's gradient points either way
      // through a surface), SPEC §8's weighting with Q_diff = 1 − Q_amb.
      VF w[3];
      for (int c = 0; c < 3; ++c)
        w[c] = hn::Add(hn::Add(hn::Mul(hn::Set(df, s.toWorld[c][0]), g[0]),
                               hn::Mul(hn::Set(df, s.toWorld[c][1]), g[1])),
                       hn::Mul(hn::Set(df, s.toWorld[c][2]), g[2]));
      const VF length2 =
          hn::Add(hn::Add(hn::Mul(w[0], w[0]), hn::Mul(w[1], w[1])), hn::Mul(w[2], w[2]));
      const VF toward = hn::Add(hn::Add(hn::Mul(w[0], hn::Set(df, s.toLight[0])),
                                        hn::Mul(w[1], hn::Set(df, s.toLight[1]))),
                                hn::Mul(w[2], hn::Set(df, s.toLight[2])));
      const auto lit = hn::Gt(length2, hn::Zero(df));
      const VF length = hn::Sqrt(hn::IfThenElse(lit, length2, hn::Set(df, 1.0f)));
      const VF cosine = hn::Div(hn::Abs(toward), length);
      const VF diffuse = hn::Mul(hn::Set(df, 1 - s.ambient), cosine);
      for (int c = 0; c < 3; ++c) {
        const VF weight = hn::Add(hn::Set(df, s.ambient), hn::Mul(diffuse, hn::Set(df, s.lightColor[c])));
        channel[c] = hn::IfThenElse(lit, hn::Mul(channel[c], weight), channel[c]);
      }
    }
    hn::Store(hn::IfThenZeroElse(transparent, channel[0]), df, b.r + i);
    hn::Store(hn::IfThenZeroElse(transparent, channel[1]), df, b.g + i);
    hn::Store(hn::IfThenZeroElse(transparent, channel[2]), df, b.b + i);
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::volume
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sv::volume {
HWY_EXPORT(ClassifySamples);

void classifySamples(const SampleSource& source, int count, SampleBatch& batch) {
  count = std::clamp(count, 0, kBatch);
  if (count == 0) return;
  // Lanes past `count` classify a copy of the first position (whole vectors are read).
  for (int i = count; i < kBatch; ++i)
    batch.x[i] = batch.x[0], batch.y[i] = batch.y[0], batch.z[i] = batch.z[0];
  HWY_DYNAMIC_DISPATCH(ClassifySamples)(source, count, batch);
}
}  // namespace sv::volume
#endif
