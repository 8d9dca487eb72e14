// Pixel shading's blocks (ShadeMode::material; Highway, per target): the attribute planes per
// lane, a block's or a batch's fragments for shade::shadeFragments, and the shaded colour written
// back — opaque, cut out by alpha, or blended — at one sample or to the samples that passed.
//
// Based on: SPEC §2 (attributes over w, perspective-correct), §5 (samples), §7–§8 (shading).
//
// Per-target include guard (Highway's convention for -inl.h files): included by tile_kernel.cpp,
// once per SIMD target, so that everything here inlines into the kernel.
#if defined(SV_RASTER_MATERIAL_BLOCKS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef SV_RASTER_MATERIAL_BLOCKS_INL_H_
#undef SV_RASTER_MATERIAL_BLOCKS_INL_H_
#else
#define SV_RASTER_MATERIAL_BLOCKS_INL_H_
#endif

#include "raster/kernel_common-inl.h"
#include "shade/shading.h"

HWY_BEFORE_NAMESPACE();
namespace sv::raster {
namespace HWY_NAMESPACE {

// ---- Pixel shading (ShadeMode::material): the kernel finds the pixels and samples that pass the
// depth test, gathers their interpolated attributes into shade::Fragments, and writes what
// shade::shadeFragments returns — opaque, cut out by alpha, or blended over the pixel.

// The attribute planes' per-lane offsets, as PlaneLanes holds the base planes'.
struct AttributeLanes {
  alignas(64) float offset[shade::kAttributeCount][kBlockPixels];
  float c0[shade::kAttributeCount], dx[shade::kAttributeCount], dy[shade::kAttributeCount];
};

// Every plane, used or not: the lanes of planes the material does not read are never read either
// (blockFragments takes only attributesUsed's), and those planes may hold stale values — binning
// stores a record's second line only when some material of the frame reads it (AttributeSetup).
HWY_INLINE void computeAttributeLanes(const AttributeSetup& a, AttributeLanes& out) {
  const hn::CappedTag<float, kBlockPixels> df;
  const hn::RebindToSigned<decltype(df)> di;
  for (int p = 0; p < shade::kAttributeCount; ++p) {
    out.c0[p] = a.planes[p].c0;
    out.dx[p] = a.planes[p].dx;
    out.dy[p] = a.planes[p].dy;
  }
  for (size_t i = 0; i < size_t(kBlockPixels); i += hn::Lanes(df)) {
    const auto lx = hn::ConvertTo(df, hn::LoadU(di, kLaneX + i));
    const auto ly = hn::ConvertTo(df, hn::LoadU(di, kLaneY + i));
    for (int p = 0; p < shade::kAttributeCount; ++p)
      hn::StoreU(hn::Add(hn::Mul(hn::Set(df, out.dx[p]), lx), hn::Mul(hn::Set(df, out.dy[p]), ly)),
                 df, out.offset[p] + i);
  }
}

// A full batch's count and the footprint gradients (per pixel, constant over the triangle).
HWY_INLINE void setGradients(const PlaneLanes& lanes, const AttributeLanes& al,
                             shade::Fragments& f) {
  f.count = kBlockPixels;
  f.qdx = lanes.dx[kInvW];
  f.qdy = lanes.dy[kInvW];
  f.udx = al.dx[shade::kU];
  f.udy = al.dy[shade::kU];
  f.vdx = al.dx[shade::kV];
  f.vdy = al.dy[shade::kV];
}

// The fragments of block (gx, gy) whose base-plane values at the top-left pixel are `base`, at
// each lane's pixel centre moved by (cx, cy) (nullptr: the centres); of the attributes only those
// in `used` (bit per shade::Attribute, shade::attributesUsed).
HWY_INLINE void blockFragments(const TriangleSetup& t, const PlaneLanes& lanes,
                               const AttributeLanes& al, const float* base, int gx, int gy,
                               const float* cx, const float* cy, unsigned used,
                               shade::Fragments& f) {
  const hn::CappedTag<float, kBlockPixels> df;
  const size_t n = hn::Lanes(df);
  const float bx = float(gx - t.minX), by = float(gy - t.minY);
  float attrBase[shade::kAttributeCount];
  for (int p = 0; p < shade::kAttributeCount; ++p)
    attrBase[p] = (al.c0[p] + al.dx[p] * bx) + al.dy[p] * by;
  const auto zero = hn::Zero(df), one = hn::Set(df, 1.0f);
  for (size_t i = 0; i < size_t(kBlockPixels); i += n) {
    const auto ox = cx ? hn::LoadU(df, cx + i) : zero, oy = cy ? hn::LoadU(df, cy + i) : zero;
    auto at = [&](float b, const float* offset, float dx, float dy) {
      return hn::Add(hn::Add(hn::Set(df, b), hn::LoadU(df, offset + i)),
                     hn::Add(hn::Mul(hn::Set(df, dx), ox), hn::Mul(hn::Set(df, dy), oy)));
    };
    const auto q = at(base[kInvW], lanes.offset[kInvW], lanes.dx[kInvW], lanes.dy[kInvW]);
    hn::StoreU(q, df, f.q + i);
    const auto w = hn::Div(one, hn::Max(q, hn::Set(df, 1e-30f)));
    for (int ch = 0; ch < kColorChannels; ++ch) {
      const auto cw =
          at(base[kRed + ch], lanes.offset[kRed + ch], lanes.dx[kRed + ch], lanes.dy[kRed + ch]);
      hn::StoreU(hn::Min(hn::Max(hn::Mul(cw, w), zero), one), df, f.color[ch] + i);
    }
    for (int p = 0; p < shade::kAttributeCount; ++p)
      if (used & (1u << p))
        hn::StoreU(at(attrBase[p], al.offset[p], al.dx[p], al.dy[p]), df, f.attribute[p] + i);
  }
  setGradients(lanes, al, f);
}

// Writes shaded colour `rgba` to the lanes of one sample plane set in `pass`: the colour itself, or
// for translucent materials rgb + (1 − a)·(what the pixel holds) (premultiplied "over").
template <class DF, class M>
HWY_INLINE void storeShaded(DF df, M pass, bool blend, const float (*rgba)[kBlockPixels], size_t i,
                            uint16_t* color) {
  const hn::RebindToSigned<DF> di;
  const hn::Rebind<uint16_t, DF> du;
  const auto pass16 = passMask16(df, pass);
  const auto keep = hn::Sub(hn::Set(df, 1.0f), hn::LoadU(df, rgba[3] + i));
  for (int ch = 0; ch < kColorChannels; ++ch) {
    uint16_t* dst = color + ch * kBlockPixels + i;
    auto c = hn::LoadU(df, rgba[ch] + i);
    if (blend) {
      const auto old = hn::Mul(hn::ConvertTo(df, hn::PromoteTo(di, hn::LoadU(du, dst))),
                               hn::Set(df, 1.0f / 65535.0f));
      c = hn::Min(hn::Add(hn::Mul(old, keep), c), hn::Set(df, 1.0f));
    }
    storeWhere(hn::DemoteTo(du, unitToLanes(df, c)), pass16, du, dst);
  }
}

// One 4×4 block at one sample per pixel; returns the pixels hidden by the depth test.
HWY_INLINE int shadeBlockMaterial(const TriangleSetup& t, const PlaneLanes& lanes,
                                  const AttributeLanes& al, const AttributeSetup& a,
                                  const shade::Environment& env, uint32_t mask, int gx, int gy,
                                  float* depth, uint16_t* color, uint32_t* visible) {
  const hn::CappedTag<float, kBlockPixels> df;
  const hn::RebindToSigned<decltype(df)> di;
  const size_t n = hn::Lanes(df);
  alignas(32) float base[8];
  blockBases(t, lanes, gx, gy, base);
  const auto maskVec = hn::Set(di, static_cast<int32_t>(mask));
  // Step 1: the depth test; nothing to shade if no pixel passes.
  uint32_t passBits = 0;
  for (size_t i = 0; i < size_t(kBlockPixels); i += n) {
    const auto covered = hn::RebindMask(df, hn::TestBit(maskVec, hn::LoadU(di, kLaneBit + i)));
    const auto z = hn::Add(hn::Set(df, base[kDepth]), hn::LoadU(df, lanes.offset[kDepth] + i));
    passBits |= laneBits(df, hn::And(covered, hn::Lt(z, hn::LoadU(df, depth + i))), i);
  }
  const int hidden = std::popcount(mask) - std::popcount(passBits);
  if (!passBits) return hidden;
  // Step 2: shade all 16 pixels at once, then write those that pass (and are not cut away).
  shade::Fragments f;
  blockFragments(t, lanes, al, base, gx, gy, nullptr, nullptr,
                 shade::attributesUsed(*a.material, env), f);
  alignas(64) float rgba[4][kBlockPixels];
  shade::shadeFragments(*a.material, env, f, rgba);
  const bool blend = a.material->alpha == shade::AlphaUse::blend;
  const bool cut = a.material->alpha == shade::AlphaUse::mask;
  // A dissolving level of detail's door (MaterialShading::door): its pixels of the block.
  const auto passVec = hn::Set(di, static_cast<int32_t>(passBits & a.material->door));
  for (size_t i = 0; i < size_t(kBlockPixels); i += n) {
    auto pass = hn::RebindMask(df, hn::TestBit(passVec, hn::LoadU(di, kLaneBit + i)));
    if (cut) pass = hn::And(pass, hn::Gt(hn::LoadU(df, rgba[3] + i), hn::Zero(df)));
    if (hn::AllFalse(df, pass)) continue;
    // Translucent surfaces are seen through: they do not hide what is drawn after them.
    if (!blend) {
      const auto z = hn::Add(hn::Set(df, base[kDepth]), hn::LoadU(df, lanes.offset[kDepth] + i));
      storeWhere(z, pass, df, depth + i);
      // A pixel this triangle now owns no longer waits for a deferred one (shadeVisible).
      if (visible) {
        const hn::RebindToUnsigned<decltype(df)> du;
        storeWhere(hn::Set(du, kNoTriangle), hn::RebindMask(du, pass), du, visible + i);
      }
    }
    storeShaded(df, pass, blend, rgba, i, color);
  }
  return hidden;
}

// Anti-aliased pixel shading, in three steps so that the pixels of several blocks of one
// triangle share the SIMD lanes of one shading call (a 200-px triangle touches some 36 blocks
// whose 16 lanes it would fill a third of): per block, which samples pass the depth test and
// where each pixel is shaded (centre, or centroid of the covered samples as shadeBlockSamples);
// then the passing pixels, 16 to a batch (TriangleRaster::flushSamples); then per block the
// shaded colour written to the samples that passed.

// Step 1 for block (gx, gy): the samples that pass, a bit per sample as the masks hold them
// (masks nullptr: all covered), and the centroid offsets (cx, cy) of partly covered pixels.
// False if none pass. `hidden` counts the covered pixels none of whose samples pass. `uniform`
// (optional): every sample of `depth` holds uniform[0] (colour sums: the clear depth), and
// uniform[1] is the largest of sampleDepth — a lane whose largest sample depth is below the
// former passes every covered sample without testing each (float addition is monotonic).
HWY_INLINE bool samplesPassing(const TriangleSetup& t, const PlaneLanes& lanes,
                               const CoverageTables& cov, const float* sampleDepth,
                               const uint32_t (*masks)[kBlockPixels], int gx, int gy,
                               const float* depth, uint32_t (*pass)[kBlockPixels], float* cx,
                               float* cy, const uint32_t (*shading)[kBlockPixels], int& hidden,
                               const float* uniform = nullptr) {
  const int samples = cov.samples;
  const uint32_t fullWord0 = fullSampleWord(samples, 0), fullWord1 = fullSampleWord(samples, 1);
  const hn::CappedTag<float, kBlockPixels> df;
  const hn::RebindToUnsigned<decltype(df)> du32;
  const size_t n = hn::Lanes(df);
  alignas(32) float base[8];
  blockBases(t, lanes, gx, gy, base);
  bool any = false;
  for (size_t i = 0; i < size_t(kBlockPixels); i += n) {
    auto m0 = hn::Set(du32, fullWord0), m1 = hn::Set(du32, fullWord1);
    if (masks) {
      m0 = hn::LoadU(du32, masks[0] + i);
      m1 = samples > 32 ? hn::LoadU(du32, masks[1] + i) : hn::Zero(du32);
    }
    const auto zPix = hn::Add(hn::Set(df, base[kDepth]), hn::LoadU(df, lanes.offset[kDepth] + i));
    auto p0 = hn::Zero(du32), p1 = p0;
    const bool allPass = uniform && hn::AllTrue(df, hn::Lt(hn::Add(zPix, hn::Set(df, uniform[1])),
                                                           hn::Set(df, uniform[0])));
    if (allPass) {
      p0 = m0;
      p1 = m1;
    }
    for (int s = 0; !allPass && s < samples; ++s) {
      const auto bit = hn::Set(du32, 1u << (s & 31));
      const auto covered = hn::RebindMask(df, hn::TestBit(s < 32 ? m0 : m1, bit));
      if (hn::AllFalse(df, covered)) continue;
      const auto z = hn::Add(zPix, hn::Set(df, sampleDepth[s]));
      const auto zOld = hn::LoadU(df, depth + size_t(s) * kBlockPixels + i);
      orSampleBit(du32, hn::RebindMask(du32, hn::And(covered, hn::Lt(z, zOld))), s, p0, p1);
    }
    hn::StoreU(p0, du32, pass[0] + i);
    hn::StoreU(p1, du32, pass[1] + i);
    const auto none = hn::Eq(hn::Or(p0, p1), hn::Zero(du32));
    hidden += int(hn::CountTrue(du32, hn::AndNot(hn::Eq(hn::Or(m0, m1), hn::Zero(du32)), none)));
    auto x = hn::Zero(df), y = x;
    if (!hn::AllTrue(du32, none)) {
      any = true;
      auto s0 = m0, s1 = m1;  // as shadeBlockSamples
      if (shading) {
        s0 = hn::LoadU(du32, shading[0] + i);
        s1 = samples > 32 ? hn::LoadU(du32, shading[1] + i) : hn::Zero(du32);
      }
      const bool full = hn::AllTrue(du32, hn::Eq(s0, hn::Set(du32, fullWord0))) &&
                        hn::AllTrue(du32, hn::Eq(s1, hn::Set(du32, fullWord1)));
      if (cov.centroid && !full) centroidOffsets(df, cov, s0, s1, x, y);
    }
    hn::StoreU(x, df, cx + i);
    hn::StoreU(y, df, cy + i);
  }
  return any;
}

// Step 3 for block (gx, gy): shaded colour `rgba` (block lanes) to the samples that passed —
// opaque, cut out where alpha is 0, or blended over the sample without writing depth. With `sums`
// (TileWork::sums: opaque only) added to the block's colour sums instead.
HWY_INLINE void writeSamples(const TriangleSetup& t, const PlaneLanes& lanes,
                             const shade::MaterialShading& m, const float* sampleDepth, int samples,
                             const uint32_t (*pass)[kBlockPixels],
                             const float (*rgba)[kBlockPixels], int gx, int gy, float* depth,
                             uint16_t* color, int32_t* sums, const int32_t* clearColor) {
  const hn::CappedTag<float, kBlockPixels> df;
  const hn::RebindToUnsigned<decltype(df)> du32;
  if (sums) {
    const hn::RebindToSigned<decltype(df)> di;
    for (size_t i = 0; i < size_t(kBlockPixels); i += hn::Lanes(df)) {
      const auto count =
          hn::BitCast(di, hn::Add(hn::PopulationCount(hn::LoadU(du32, pass[0] + i)),
                                  hn::PopulationCount(hn::LoadU(du32, pass[1] + i))));
      hn::Vec<decltype(di)> c[kColorChannels];
      for (int ch = 0; ch < kColorChannels; ++ch)
        c[ch] = unitToLanes(df, hn::LoadU(df, rgba[ch] + i));
      addToSums(di, count, c, clearColor, sums, i);
    }
    return;
  }
  const size_t n = hn::Lanes(df);
  const bool blend = m.alpha == shade::AlphaUse::blend;
  const bool cut = m.alpha == shade::AlphaUse::mask;
  const hn::RebindToSigned<decltype(df)> di;
  alignas(32) float base[8];
  blockBases(t, lanes, gx, gy, base);
  for (size_t i = 0; i < size_t(kBlockPixels); i += n) {
    const auto p0 = hn::LoadU(du32, pass[0] + i), p1 = hn::LoadU(du32, pass[1] + i);
    if (hn::AllTrue(du32, hn::Eq(hn::Or(p0, p1), hn::Zero(du32)))) continue;
    // All lanes, or a dissolving level of detail's door (MaterialShading::door).
    auto shown = hn::RebindMask(df, hn::TestBit(hn::Set(di, static_cast<int32_t>(m.door)),
                                                hn::LoadU(di, kLaneBit + i)));
    if (cut) shown = hn::And(shown, hn::Gt(hn::LoadU(df, rgba[3] + i), hn::Zero(df)));
    const auto zPix = hn::Add(hn::Set(df, base[kDepth]), hn::LoadU(df, lanes.offset[kDepth] + i));
    for (int s = 0; s < samples; ++s) {
      const auto passed = hn::And(
          shown, hn::RebindMask(df, hn::TestBit(s < 32 ? p0 : p1, hn::Set(du32, 1u << (s & 31)))));
      if (hn::AllFalse(df, passed)) continue;
      if (!blend)
        storeWhere(hn::Add(zPix, hn::Set(df, sampleDepth[s])), passed, df,
                   depth + size_t(s) * kBlockPixels + i);
      storeShaded(df, passed, blend, rgba, i, color + size_t(s) * kColorPerBlock);
    }
  }
}

// Step 2's fragments: up to 16 pixels of one triangle from anywhere in the tile — pixel i in the
// block whose top-left pixel is (bx[i], by[i]) from the planes' origin, at lane lane[i], moved by
// (cx[i], cy[i]) — with exactly blockFragments' float operations, so that a pixel shades the same
// in a batch as it would in its block.
HWY_INLINE void batchFragments(const PlaneLanes& lanes, const AttributeLanes& al, const float* bx,
                               const float* by, const int32_t* lane, const float* cx,
                               const float* cy, unsigned used, shade::Fragments& f) {
  const hn::CappedTag<float, kBlockPixels> df;
  const hn::RebindToSigned<decltype(df)> di;
  const size_t n = hn::Lanes(df);
  const auto zero = hn::Zero(df), one = hn::Set(df, 1.0f);
  for (size_t i = 0; i < size_t(kBlockPixels); i += n) {
    const auto X = hn::LoadU(df, bx + i), Y = hn::LoadU(df, by + i);
    const auto l = hn::LoadU(di, lane + i);
    const auto ox = hn::LoadU(df, cx + i), oy = hn::LoadU(df, cy + i);
    auto at = [&](float c0, float dx, float dy, const float* offset) {
      const auto base = hn::Add(hn::Add(hn::Set(df, c0), hn::Mul(hn::Set(df, dx), X)),
                                hn::Mul(hn::Set(df, dy), Y));
      return hn::Add(hn::Add(base, hn::GatherIndex(df, offset, l)),
                     hn::Add(hn::Mul(hn::Set(df, dx), ox), hn::Mul(hn::Set(df, dy), oy)));
    };
    const auto q = at(lanes.c0[kInvW], lanes.dx[kInvW], lanes.dy[kInvW], lanes.offset[kInvW]);
    hn::StoreU(q, df, f.q + i);
    const auto w = hn::Div(one, hn::Max(q, hn::Set(df, 1e-30f)));
    for (int ch = 0; ch < kColorChannels; ++ch) {
      const int p = kRed + ch;
      const auto cw = at(lanes.c0[p], lanes.dx[p], lanes.dy[p], lanes.offset[p]);
      hn::StoreU(hn::Min(hn::Max(hn::Mul(cw, w), zero), one), df, f.color[ch] + i);
    }
    for (int p = 0; p < shade::kAttributeCount; ++p)
      if (used & (1u << p))
        hn::StoreU(at(al.c0[p], al.dx[p], al.dy[p], al.offset[p]), df, f.attribute[p] + i);
  }
  setGradients(lanes, al, f);
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::raster
HWY_AFTER_NAMESPACE();

#endif  // SV_RASTER_MATERIAL_BLOCKS_INL_H_
