// The per-block pixel operations of the tile kernel (Highway, per target): what happens to the
// covered pixels of one 4×4 block — overdraw count, depth test and Gouraud colour at one sample or
// N sample planes (anti-aliasing), visibility (the winner recorded for deferred shading), the
// levels view.
//
// Based on: SPEC §4 (Z-buffer), §5 (samples: depth per sample, colour once per pixel at its centre
// or centroid), §8 (Gouraud colour, perspective-correct).
//
// Per-target include guard (Highway's convention for -inl.h files): included by tile_kernel.cpp,
// once per SIMD target, so that everything here inlines into the kernel.
#if defined(SV_RASTER_BLOCK_OPS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef SV_RASTER_BLOCK_OPS_INL_H_
#undef SV_RASTER_BLOCK_OPS_INL_H_
#else
#define SV_RASTER_BLOCK_OPS_INL_H_
#endif

#include "raster/kernel_common-inl.h"

HWY_BEFORE_NAMESPACE();
namespace sv::raster {
namespace HWY_NAMESPACE {

// Overdraw count: +1 in the red channel of every pixel set in `mask` (no depth test).
HWY_INLINE void countBlock(uint32_t mask, uint16_t* color) {
  for (; mask; mask &= mask - 1) ++color[std::countr_zero(mask)];
}

// Depth test ("less") and Gouraud colour for the pixels of one 4×4 block set in `mask` (kFull:
// all 16, untested). base[p · stride] holds plane p's value at the block's top-left pixel
// (blockBases, or runBases for a run of blocks); `depth` and `color` point at the block's storage.
// Returns how many of the pixels failed the depth test (hidden fragments, as every depth-testing
// block operation here: hybrid masking wakes on them, drawLists).
template <bool kFull = false>
HWY_INLINE int gouraudBlock(const PlaneLanes& lanes, const float* base, size_t stride,
                            uint32_t mask, float* depth, uint16_t* color) {
  const hn::CappedTag<float, kBlockPixels> df;
  const hn::RebindToSigned<decltype(df)> di;
  const hn::Rebind<uint16_t, decltype(df)> du;
  const size_t n = hn::Lanes(df);
  const auto maskVec = hn::Set(di, static_cast<int32_t>(mask));
  const auto one = hn::Set(df, 1.0f);
  uint32_t passed = 0;
  for (size_t i = 0; i < size_t(kBlockPixels); i += n) {
    // SPEC §4: Z-buffer — depth is a §2 parameter, linear in screen space.
    const auto z =
        hn::Add(hn::Set(df, base[kDepth * stride]), hn::LoadU(df, lanes.offset[kDepth] + i));
    const auto zOld = hn::LoadU(df, depth + i);
    auto pass = hn::Lt(z, zOld);
    if constexpr (!kFull)
      pass = hn::And(hn::RebindMask(df, hn::TestBit(maskVec, hn::LoadU(di, kLaneBit + i))), pass);
    if (hn::AllFalse(df, pass)) continue;
    passed |= laneBits(df, pass, i);
    storeWhere(z, pass, df, depth + i);
    // SPEC §2: perspective-correct colour = (colour/w) / (1/w).
    const auto w = hn::Div(
        one, hn::Add(hn::Set(df, base[kInvW * stride]), hn::LoadU(df, lanes.offset[kInvW] + i)));
    const auto pass16 = passMask16(df, pass);
    for (int ch = 0; ch < kColorChannels; ++ch) {
      const auto cw = hn::Add(hn::Set(df, base[(kRed + ch) * stride]),
                              hn::LoadU(df, lanes.offset[kRed + ch] + i));
      storeWhere(hn::DemoteTo(du, colorToLanes(df, cw, w)), pass16, du,
                 color + ch * kBlockPixels + i);
    }
  }
  return std::popcount(mask) - std::popcount(passed);
}

// The same for the pixels of the block at (gx, gy) set in `mask`.
HWY_INLINE int shadeBlock(const TriangleSetup& t, const PlaneLanes& lanes, uint32_t mask, int gx,
                          int gy, float* depth, uint16_t* color) {
  alignas(32) float base[8];
  blockBases(t, lanes, gx, gy, base);
  return gouraudBlock(lanes, base, 1, mask, depth, color);
}

// The centroid of each lane's covered samples relative to its pixel centre, in pixels (zero for a
// lane whose samples are all covered):
//     (Σ offsets in 1/256 px, an exact integer) · (1 / (count · 256)).
template <class DF, class VU, class V>
HWY_INLINE void centroidOffsets(DF df, const CoverageTables& cov, VU m0, VU m1, V& cx, V& cy) {
  const hn::RebindToSigned<DF> di;
  const hn::RebindToUnsigned<DF> du32;
  const int samples = cov.samples;
  auto sx = hn::Zero(di), sy = sx, count = sx;
  for (int s = 0; s < samples; ++s) {
    const auto covered =
        hn::RebindMask(di, hn::TestBit(s < 32 ? m0 : m1, hn::Set(du32, 1u << (s & 31))));
    sx = hn::Add(sx, hn::IfThenElseZero(covered, hn::Set(di, cov.offsetX[s])));
    sy = hn::Add(sy, hn::IfThenElseZero(covered, hn::Set(di, cov.offsetY[s])));
    count = hn::Sub(count, hn::VecFromMask(di, covered));
  }
  const auto partial = hn::RebindMask(df, hn::Lt(count, hn::Set(di, samples)));
  const auto scale =
      hn::Div(hn::Set(df, 1.0f),
              hn::Mul(hn::ConvertTo(df, hn::Max(count, hn::Set(di, 1))), hn::Set(df, 256.0f)));
  cx = hn::IfThenElseZero(partial, hn::Mul(hn::ConvertTo(df, sx), scale));
  cy = hn::IfThenElseZero(partial, hn::Mul(hn::ConvertTo(df, sy), scale));
}

// The same with N samples per pixel (SPEC §5): masks[w][p] holds pixel p's samples 32·w … 32·w + 31
// (masks == nullptr: every sample of every pixel). Depth is tested per sample at its position,
// z_s = z(centre) + sampleDepth[s]; colour is shaded once per pixel and written to the samples that
// pass — at the centre of a fully covered pixel, and (CoverageTables::centroid) at the centroid of
// the covered samples of a partly covered one, nearer the triangle than the centre, where colour
// is extrapolated.
// The planes are evaluated at the centroid as (base + offset) + (dx·cx + dy·cy).
// `shading`: the triangle's coverage that places the shading position when `masks` holds less of
// it (priority masking removes occupied samples, but the Z-buffer shades the same pixel at the
// centroid of all it covers; the two must agree); nullptr: `masks`. Returns the covered pixels
// none of whose samples passed.
// With `sums` (TileWork::sums) the samples are tested against `depth` alone, which then holds the
// clear depth, and added to the sums instead of written.
HWY_INLINE int shadeBlockSamples(const TriangleSetup& t, const PlaneLanes& lanes,
                                 const CoverageTables& cov, const float* sampleDepth,
                                 const uint32_t (*masks)[kBlockPixels], int gx, int gy,
                                 float* depth, uint16_t* color,
                                 const uint32_t (*shading)[kBlockPixels], int32_t* sums,
                                 const int32_t* clearColor) {
  const int samples = cov.samples;
  // The words of a full mask.
  const uint32_t fullWord0 = fullSampleWord(samples, 0), fullWord1 = fullSampleWord(samples, 1);
  const hn::CappedTag<float, kBlockPixels> df;
  const hn::RebindToSigned<decltype(df)> di;
  const hn::RebindToUnsigned<decltype(df)> du32;
  const hn::Rebind<uint16_t, decltype(df)> du;
  const size_t n = hn::Lanes(df);
  alignas(32) float base[8];
  blockBases(t, lanes, gx, gy, base);
  const auto one = hn::Set(df, 1.0f), tiny = hn::Set(df, 1e-30f);
  int hidden = 0;
  for (size_t i = 0; i < size_t(kBlockPixels); i += n) {
    auto m0 = hn::Set(du32, ~0u), m1 = m0;
    if (masks) {
      m0 = hn::LoadU(du32, masks[0] + i);
      m1 = samples > 32 ? hn::LoadU(du32, masks[1] + i) : hn::Zero(du32);
      if (hn::AllTrue(du32, hn::Eq(hn::Or(m0, m1), hn::Zero(du32)))) continue;
    }
    const auto zPix = hn::Add(hn::Set(df, base[kDepth]), hn::LoadU(df, lanes.offset[kDepth] + i));
    // The shading position, relative to the pixel centre.
    auto cx = hn::Zero(df), cy = cx;
    auto s0 = m0, s1 = m1;
    if (shading) {
      s0 = hn::LoadU(du32, shading[0] + i);
      s1 = samples > 32 ? hn::LoadU(du32, shading[1] + i) : hn::Zero(du32);
    }
    const bool full = !masks || (hn::AllTrue(du32, hn::Eq(s0, hn::Set(du32, fullWord0))) &&
                                 hn::AllTrue(du32, hn::Eq(s1, hn::Set(du32, fullWord1))));
    if (cov.centroid && !full) centroidOffsets(df, cov, s0, s1, cx, cy);
    auto at = [&](int plane) {
      return hn::Add(hn::Add(hn::Set(df, base[plane]), hn::LoadU(df, lanes.offset[plane] + i)),
                     hn::Add(hn::Mul(hn::Set(df, lanes.dx[plane]), cx),
                             hn::Mul(hn::Set(df, lanes.dy[plane]), cy)));
    };
    // Outside the triangle 1/w is extrapolated and may reach 0; the clamp keeps w finite.
    const auto w = hn::Div(one, hn::Max(at(kInvW), tiny));
    hn::Vec<decltype(di)> c32[kColorChannels];
    hn::Vec<decltype(du)> c16[kColorChannels];
    for (int ch = 0; ch < kColorChannels; ++ch) {
      c32[ch] = colorToLanes(df, at(kRed + ch), w);
      c16[ch] = hn::DemoteTo(du, c32[ch]);
    }
    auto anyPass = hn::FirstN(df, 0);
    auto count = hn::Zero(di);  // samples passed, with sums
    for (int s = 0; s < samples; ++s) {
      const auto covered =
          hn::RebindMask(df, hn::TestBit(s < 32 ? m0 : m1, hn::Set(du32, 1u << (s & 31))));
      if (hn::AllFalse(df, covered)) continue;
      float* zPlane = depth + size_t(s) * kBlockPixels + i;
      const auto z = hn::Add(zPix, hn::Set(df, sampleDepth[s]));
      const auto zOld = hn::LoadU(df, zPlane);
      const auto pass = hn::And(covered, hn::Lt(z, zOld));
      if (hn::AllFalse(df, pass)) continue;
      anyPass = hn::Or(anyPass, pass);
      if (sums) {
        count = hn::Sub(count, hn::VecFromMask(di, hn::RebindMask(di, pass)));
        continue;
      }
      storeWhere(z, pass, df, zPlane);
      const auto pass16 = passMask16(df, pass);
      for (int ch = 0; ch < kColorChannels; ++ch)
        storeWhere(c16[ch], pass16, du, color + size_t(s) * kColorPerBlock + ch * kBlockPixels + i);
    }
    hidden += int(hn::CountTrue(du32, hn::Ne(hn::Or(m0, m1), hn::Zero(du32))) -
                  hn::CountTrue(df, anyPass));
    if (sums) addToSums(di, count, c32, clearColor, sums, i);
  }
  return hidden;
}

// Visibility (PixelOp::visibility): the depth test alone, recording triangle `id` in the pixels it
// wins — the SPEC §1 split of visibility from shading that the image generators of the seeds made
// in hardware: each pixel is shaded once, by its final winner, however many triangles covered it.
// `zBase`: the depth plane at the block's top-left pixel (blockBases, runBases); kFull: all 16
// pixels, untested. Returns the pixels hidden by the depth test.
template <bool kFull = false>
HWY_INLINE int visibleBlockAt(const PlaneLanes& lanes, float zBase, uint32_t mask, uint32_t id,
                              float* depth, uint32_t* visible) {
  const hn::CappedTag<float, kBlockPixels> df;
  const hn::RebindToSigned<decltype(df)> di;
  const hn::RebindToUnsigned<decltype(df)> du;
  const size_t n = hn::Lanes(df);
  const auto maskVec = hn::Set(di, static_cast<int32_t>(mask));
  const auto idVec = hn::Set(du, id);
  uint32_t passed = 0;
  for (size_t i = 0; i < size_t(kBlockPixels); i += n) {
    const auto z = hn::Add(hn::Set(df, zBase), hn::LoadU(df, lanes.offset[kDepth] + i));
    auto pass = hn::Lt(z, hn::LoadU(df, depth + i));
    if constexpr (!kFull)
      pass = hn::And(hn::RebindMask(df, hn::TestBit(maskVec, hn::LoadU(di, kLaneBit + i))), pass);
    passed |= laneBits(df, pass, i);
    storeWhere(z, pass, df, depth + i);
    storeWhere(idVec, hn::RebindMask(du, pass), du, visible + i);
  }
  return std::popcount(mask) - std::popcount(passed);
}

HWY_INLINE int visibleBlock(const TriangleSetup& t, const PlaneLanes& lanes, uint32_t mask, int gx,
                            int gy, uint32_t id, float* depth, uint32_t* visible) {
  alignas(32) float base[8];
  blockBases(t, lanes, gx, gy, base);
  return visibleBlockAt(lanes, base[kDepth], mask, id, depth, visible);
}

// The levels view (PixelOp::levels): the depth test, and in the pixels that pass, `level` in the
// red channel (ShadeMode::levels). Returns the pixels hidden by the depth test.
HWY_INLINE int levelBlock(const TriangleSetup& t, const PlaneLanes& lanes, uint32_t mask, int gx,
                          int gy, int level, float* depth, uint16_t* color) {
  alignas(32) float base[8];
  blockBases(t, lanes, gx, gy, base);
  int hidden = 0;
  for (int l = 0; l < kBlockPixels; ++l) {
    if (!(mask >> l & 1)) continue;
    const float z = base[kDepth] + lanes.offset[kDepth][l];
    if (!(z < depth[l])) {
      ++hidden;
      continue;
    }
    depth[l] = z;
    color[l] = uint16_t(level);
    color[kBlockPixels + l] = color[2 * kBlockPixels + l] = 0;
  }
  return hidden;
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::raster
HWY_AFTER_NAMESPACE();

#endif  // SV_RASTER_BLOCK_OPS_INL_H_
