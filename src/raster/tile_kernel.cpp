// The tile kernel: recursive 2×2 subdivision with coverage functions, 4×4 leaves, depth test and
// Gouraud shading, compiled once per SIMD target (Highway) and dispatched once per tile.
//
// Based on: SPEC §3.1 (seed 000 eqs. 2–5), §3.2 (eqs. 6–9), §3.3 (seed 004 eq. 14), §3.5, §4;
// Mesa llvmpipe's lp_rast_tri_tmp.h and Abrash 2009 (Larrabee) for the trivial accept/reject
// formulation of the same test.
//
// Symbols. For an edge e(px, py) = c + sX·px + sY·py (setup.h), a window of n×n pixels is kept by
// the value tl of e at the centre of its top-left pixel. Seed 000's coverage function is
//     d = e(x_c, y_c) + ε,   ε = (|A|·a + |B|·b)/2,   a = b = n − 1 (α = β = 0: point sampling)
// — the largest value of e over the window's pixel centres. With sX⁺ = max(sX, 0), sX⁻ = min(sX,
// 0):
//     d      = tl + (sX⁺ + sY⁺)·(n − 1)        d < 0   → the window is outside: reject
//     d − 2ε = tl + (sX⁻ + sY⁻)·(n − 1)        d ≥ 2ε  → inside this edge: drop the edge below here
// A child of size h = n/2 at (cx, cy) ∈ {0,1}² has tl' = tl + cx·sX·h + cy·sY·h (seed 000 eq. 1),
// so its d' = d − h·|sX|·e_A − h·|sY|·e_B + … is seed 000's eq. 8 with the ε of the child folded
// in; we carry tl rather than d because it is the same for every level's ε (one add per edge per
// child, as the seed counts). All in exact int64 (budget in geometry/setup.h).
//
// Departure from the seed: the last two levels (2×2 and 1×1 windows) are unrolled into one 4×4 leaf
// whose 16 pixel centres are tested at once in SIMD lanes; the result is the same set of pixels.
//
// Anti-aliasing (SPEC §3.2 aperture α = β = 1, §5 masks). With N samples per pixel the windows are
// the pixel *squares* rather than their centres: in the geometric edge value E = e + bias (e with
// the fill rule's −1 taken back out) and N1 = |sX| + |sY| = 256·S, S = |a| + |b|, a pixel lies
// wholly outside the edge iff E ≤ −N1/2 and wholly inside iff E ≥ N1/2 (every sample is within ½
// of the centre in the L1 norm), so the window tests gain the constants H − 1 + bias and −H + bias
// (H = N1/2 = 128·S). A leaf pixel reads each crossing edge's mask from the row (sign quadrant,
// slope ⌊32·|a|/S⌋) of coverage_masks.h at distance cell q = ⌊D·|E|/N1⌋ = ⌊(|E| >> 1) / S⌋ for
// the table's D = 128 cells, mirrored for negative E exactly as EdgeMaskTable::mask does, so
// reversed edges read complementary masks; q is estimated in float and corrected exactly in
// integers. The pixel's mask is the AND, cut to the triangle's box (see leafSamples).

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/tile_kernel.cpp"
#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstring>

#include "hwy/cache_control.h"
#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"
#include "raster/framebuffer.h"
#include "raster/occupancy.h"
#include "raster/rasterizer.h"

HWY_BEFORE_NAMESPACE();
namespace sv::raster {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using geometry::kMaxEdges;
using geometry::Plane;
using geometry::TriangleSetup;

constexpr int32_t kLaneBit[kBlockPixels] = {1 << 0,  1 << 1,  1 << 2,  1 << 3, 1 << 4,  1 << 5,
                                            1 << 6,  1 << 7,  1 << 8,  1 << 9, 1 << 10, 1 << 11,
                                            1 << 12, 1 << 13, 1 << 14, 1 << 15};
// Lane c of a split is child (c & 1, c >> 1): all-ones where that child steps in x, in y.
template <class T>
constexpr T kChildMaskX[4] = {0, T(-1), 0, T(-1)};
template <class T>
constexpr T kChildMaskY[4] = {0, 0, T(-1), T(-1)};
constexpr int32_t kLaneX[kBlockPixels] = {0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3};
constexpr int32_t kLaneY[kBlockPixels] = {0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3};

// What TriangleRaster does with a covered pixel (ShadeMode, refined): count it; depth-test and
// write Gouraud colour; depth-test and shade it now (shade::shadeFragments); or depth-test and
// record which triangle won (visibility), to be shaded once per pixel when the tile's triangles are
// all drawn (shadeVisible).
enum class PixelOp : uint8_t { overdraw, gouraud, material, visibility, levels };

// Visibility: "no triangle recorded since the last shading pass".
constexpr uint32_t kNoTriangle = ~0u;

// Deferred shading's list of the triangles that won pixels since the last shading pass, in draw
// order, each with its box in the tile's 4×4 blocks: shadeVisible reads the blocks of each box for
// the pixels that still record the triangle — the triangle's pixels, batched without searching the
// tile for them. Scanning the whole tile costs the same however many triangles there are, the
// list's reads grow with their boxes' blocks: past kBudget blocks in all (4 a block — large
// triangles, or several layers) the scan is the cheaper. docs/performance.md.
struct WinnerList {
  static constexpr int kBudget = 4 * kBlocksPerTileSide * kBlocksPerTileSide;
  struct Entry {
    uint32_t id;                 // setup storage index
    uint8_t bx0, by0, bx1, by1;  // the box's first and last block column and row
  };
  int count = 0, blocks = 0;
  Entry entry[kBudget];  // (a box holds a block at least)

  // Triangle `id`, which won pixels in the tile-local pixel box [x0, x1] × [y0, y1].
  void add(uint32_t id, int x0, int y0, int x1, int y1) {
    if (blocks > kBudget) return;  // the scan's, for the rest of the pass
    const int bx0 = x0 >> kBlockLog2, by0 = y0 >> kBlockLog2;
    const int bx1 = x1 >> kBlockLog2, by1 = y1 >> kBlockLog2;
    blocks += (bx1 - bx0 + 1) * (by1 - by0 + 1);
    if (blocks <= kBudget)
      entry[count++] = {id, uint8_t(bx0), uint8_t(by0), uint8_t(bx1), uint8_t(by1)};
  }
  // Whether shadeVisible reads the list rather than scanning the tile.
  bool useful() const { return blocks <= kBudget; }
  void reset() { count = blocks = 0; }
};

struct TileContext {
  int originX, originY;  // pixel coordinates of the tile's top-left pixel
  float* depth;
  uint16_t* color;
  RasterStats* stats;
  const CoverageTables* coverage;         // anti-aliasing, or nullptr
  int samples;                            // per pixel: 1, or coverage->samples
  const shade::Environment* environment;  // ShadeMode::material
  // ShadeMode::material at one sample: the winning triangle per pixel (setup storage index, or
  // kNoTriangle), laid out as depth; and the records it indexes.
  uint32_t* visible;
  const TriangleSetup* setups;
  const AttributeSetup* attributes;
  // Priority masking (SPEC §4): the tile's occupied windows, or nullptr (Z-buffer alone); with
  // `hybrid`, windows are dropped by their depth bounds instead of their occupancy alone.
  Occupancy* occupancy;
  bool hybrid;
  // Colour sums (TileWork::sums), or nullptr; then `clearPlanes` holds the clear depth for every
  // sample of a block (what an unwritten sample holds: the depth test's only opponent) and
  // `clearColor` the clear colour each unwritten sample contributes to a sum.
  int32_t* sums = nullptr;
  float* clearPlanes = nullptr;
  int32_t clearColor[kColorChannels] = {};
  // Deferred shading: the triangles that won pixels, or nullptr (WinnerList).
  WinnerList* winners = nullptr;
};

// Adds `count` samples of colour `c` (16-bit values in int32 lanes) to a block's colour sums in
// place of as many samples of the clear colour (TileWork::sums; the sums start at N × clear).
template <class DI, class VI>
HWY_INLINE void addToSums(DI di, VI count, const VI* c, const int32_t* clear, int32_t* sums,
                          size_t i) {
  for (int ch = 0; ch < kColorChannels; ++ch) {
    int32_t* dst = sums + ch * kBlockPixels + i;
    hn::StoreU(hn::Add(hn::LoadU(di, dst), hn::Mul(count, hn::Sub(c[ch], hn::Set(di, clear[ch])))),
               di, dst);
  }
}

// Parameters are evaluated per 4×4 block as base + offset: base = (c0 + dx·X) + dy·Y at the block's
// top-left pixel (X, Y relative to the plane's origin), offset = dx·lx + dy·ly per lane, computed
// once per triangle. Every target, and the scalar reference in tests/support, computes exactly
// these float operations in this order, which is what makes them bit-identical.
enum PlaneIndex { kDepth, kInvW, kRed, kGreen, kBlue, kPlaneCount };

struct PlaneLanes {
  alignas(64) float offset[kPlaneCount][kBlockPixels];
  // The planes' c0, dx, dy side by side, so a block's five bases are one vector expression.
  alignas(32) float c0[8], dx[8], dy[8];
};

// The lanes of `m` (at most 16: one 4×4 block's worth from lane i on) as bits, shifted to bit i.
template <class D, class M>
HWY_INLINE uint32_t laneBits(D d, M m, size_t i) {
  uint8_t bits[8] = {};
  hn::StoreMaskBits(d, m, bits);
  return (uint32_t(bits[0]) | uint32_t(bits[1]) << 8) << i;
}

// Sets sample s's bit, in the coverage masks' two words (w0: samples 0–31, w1: 32–63), in the
// lanes of `m`.
template <class DU, class M, class VU>
HWY_INLINE void orSampleBit(DU du, M m, int s, VU& w0, VU& w1) {
  const auto bit = hn::IfThenElseZero(m, hn::Set(du, 1u << (s & 31)));
  if (s < 32)
    w0 = hn::Or(w0, bit);
  else
    w1 = hn::Or(w1, bit);
}

HWY_INLINE const Plane& planeOf(const TriangleSetup& t, int p) {
  const Plane* planes[kPlaneCount] = {&t.depth, &t.invW, &t.red, &t.green, &t.blue};
  return *planes[p];
}

HWY_INLINE void computePlaneLanes(const TriangleSetup& t, PlaneLanes& out) {
  for (int p = 0; p < 8; ++p) {
    const Plane pl = p < kPlaneCount ? planeOf(t, p) : Plane{0, 0, 0};
    out.c0[p] = pl.c0;
    out.dx[p] = pl.dx;
    out.dy[p] = pl.dy;
  }
  const hn::CappedTag<float, kBlockPixels> df;
  const hn::RebindToSigned<decltype(df)> di;
  for (size_t i = 0; i < size_t(kBlockPixels); i += hn::Lanes(df)) {
    const auto lx = hn::ConvertTo(df, hn::LoadU(di, kLaneX + i));
    const auto ly = hn::ConvertTo(df, hn::LoadU(di, kLaneY + i));
    for (int p = 0; p < kPlaneCount; ++p) {
      const Plane& pl = planeOf(t, p);
      hn::StoreU(hn::Add(hn::Mul(hn::Set(df, pl.dx), lx), hn::Mul(hn::Set(df, pl.dy), ly)), df,
                 out.offset[p] + i);
    }
  }
}

// Overdraw count: +1 in the red channel of every pixel set in `mask` (no depth test).
HWY_INLINE void countBlock(uint32_t mask, uint16_t* color) {
  for (; mask; mask &= mask - 1) ++color[std::countr_zero(mask)];
}

// The five plane values (c0 + dx·X) + dy·Y at a block's top-left pixel (gx, gy), one lane per
// plane.
HWY_INLINE void blockBases(const TriangleSetup& t, const PlaneLanes& lanes, int gx, int gy,
                           float* base) {
  const hn::CappedTag<float, 8> d8;
  const auto bx = hn::Set(d8, float(gx - t.minX)), by = hn::Set(d8, float(gy - t.minY));
  for (size_t p = 0; p < 8; p += hn::Lanes(d8))
    hn::Store(hn::Add(hn::Add(hn::Load(d8, lanes.c0 + p), hn::Mul(hn::Load(d8, lanes.dx + p), bx)),
                      hn::Mul(hn::Load(d8, lanes.dy + p), by)),
              d8, base + p);
}

// Perspective-correct colour (colour/w)·w, clamped to [0, 1], as 16-bit linear light in int32
// lanes. Float → 16-bit by the magic-number trick: for 0 ≤ v < 2^23, the float v + 2^23 holds
// round-to-nearest-even(v) in its low mantissa bits (no range fix-ups, unlike ConvertTo).
template <class DF, class V>
HWY_INLINE auto colorToLanes(DF df, V cw, V w) {
  const hn::RebindToSigned<DF> di;
  const auto c = hn::Min(hn::Max(hn::Mul(cw, w), hn::Zero(df)), hn::Set(df, 1.0f));
  return hn::And(
      hn::BitCast(di, hn::Add(hn::Mul(c, hn::Set(df, 65535.0f)), hn::Set(df, 8388608.0f))),
      hn::Set(di, 0xFFFF));
}

// Channel ch at the pixel centres of lanes i… .
template <class DF, class V>
HWY_INLINE auto colorLanes(DF df, const PlaneLanes& lanes, const float* base, int ch, size_t i,
                           V w) {
  const auto cw = hn::Add(hn::Set(df, base[kRed + ch]), hn::LoadU(df, lanes.offset[kRed + ch] + i));
  return colorToLanes(df, cw, w);
}

// Depth test ("less") and Gouraud colour for the pixels of one 4×4 block set in `mask`.
// (gx, gy) is the block's top-left pixel; `depth` and `color` point at the block's storage.
// Returns how many of the pixels failed the depth test (hidden fragments, as every depth-testing
// block operation here: hybrid masking wakes on them, drawLists).
HWY_INLINE int shadeBlock(const TriangleSetup& t, const PlaneLanes& lanes, uint32_t mask, int gx,
                          int gy, float* depth, uint16_t* color) {
  const hn::CappedTag<float, kBlockPixels> df;
  const hn::RebindToSigned<decltype(df)> di;
  const hn::Rebind<uint16_t, decltype(df)> du;
  const size_t n = hn::Lanes(df);
  alignas(32) float base[8];
  blockBases(t, lanes, gx, gy, base);
  const auto maskVec = hn::Set(di, static_cast<int32_t>(mask));
  const auto one = hn::Set(df, 1.0f);
  int hidden = 0;
  for (size_t i = 0; i < size_t(kBlockPixels); i += n) {
    const auto covered = hn::TestBit(maskVec, hn::LoadU(di, kLaneBit + i));
    if (hn::AllFalse(di, covered)) continue;
    // SPEC §4: Z-buffer — depth is a §2 parameter, linear in screen space.
    const auto z = hn::Add(hn::Set(df, base[kDepth]), hn::LoadU(df, lanes.offset[kDepth] + i));
    const auto zOld = hn::LoadU(df, depth + i);
    const auto pass = hn::And(hn::RebindMask(df, covered), hn::Lt(z, zOld));
    hidden += int(hn::CountTrue(di, covered) - hn::CountTrue(df, pass));
    if (hn::AllFalse(df, pass)) continue;
    hn::StoreU(hn::IfThenElse(pass, z, zOld), df, depth + i);
    // SPEC §2: perspective-correct colour = (colour/w) / (1/w).
    const auto w =
        hn::Div(one, hn::Add(hn::Set(df, base[kInvW]), hn::LoadU(df, lanes.offset[kInvW] + i)));
    const auto passI = hn::RebindMask(di, pass);
    for (int ch = 0; ch < kColorChannels; ++ch) {
      uint16_t* dst = color + ch * kBlockPixels + i;
      const auto old = hn::PromoteTo(di, hn::LoadU(du, dst));
      hn::StoreU(
          hn::DemoteTo(du, hn::IfThenElse(passI, colorLanes(df, lanes, base, ch, i, w), old)), du,
          dst);
    }
  }
  return hidden;
}

// The centroid of each lane's covered samples relative to its pixel centre, in pixels (zero for a
// lane whose samples are all covered): (Σ offsets in 1/256 px, an exact integer) · (1 / (count ·
// 256)).
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
  const hn::Rebind<int16_t, decltype(df)> d16;
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
      hn::BlendedStore(z, pass, df, zPlane);
      // The pass mask in 16-bit lanes (−1 stays −1 under the saturating demotion), then masked
      // stores: a third of the instructions of widening, blending and narrowing each channel.
      const auto pass16 = hn::MaskFromVec(
          hn::BitCast(du, hn::DemoteTo(d16, hn::VecFromMask(di, hn::RebindMask(di, pass)))));
      for (int ch = 0; ch < kColorChannels; ++ch)
        hn::BlendedStore(c16[ch], pass16, du,
                         color + size_t(s) * kColorPerBlock + ch * kBlockPixels + i);
    }
    hidden += int(hn::CountTrue(du32, hn::Ne(hn::Or(m0, m1), hn::Zero(du32))) -
                  hn::CountTrue(df, anyPass));
    if (sums) addToSums(di, count, c32, clearColor, sums, i);
  }
  return hidden;
}

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

// 0…1 → 16-bit lanes (colorToLanes' rounding, for a value already in range).
template <class DF, class V>
HWY_INLINE auto unitToLanes(DF df, V c) {
  const hn::RebindToSigned<DF> di;
  return hn::And(
      hn::BitCast(di, hn::Add(hn::Mul(c, hn::Set(df, 65535.0f)), hn::Set(df, 8388608.0f))),
      hn::Set(di, 0xFFFF));
}

// Writes shaded colour `rgba` to the lanes of one sample plane set in `pass`: the colour itself, or
// for translucent materials rgb + (1 − a)·(what the pixel holds) (premultiplied "over").
template <class DF, class M>
HWY_INLINE void storeShaded(DF df, M pass, bool blend, const float (*rgba)[kBlockPixels], size_t i,
                            uint16_t* color) {
  const hn::RebindToSigned<DF> di;
  const hn::Rebind<uint16_t, DF> du;
  const hn::Rebind<int16_t, DF> d16;
  const auto pass16 = hn::MaskFromVec(
      hn::BitCast(du, hn::DemoteTo(d16, hn::VecFromMask(di, hn::RebindMask(di, pass)))));
  const auto keep = hn::Sub(hn::Set(df, 1.0f), hn::LoadU(df, rgba[3] + i));
  for (int ch = 0; ch < kColorChannels; ++ch) {
    uint16_t* dst = color + ch * kBlockPixels + i;
    auto c = hn::LoadU(df, rgba[ch] + i);
    if (blend) {
      const auto old = hn::Mul(hn::ConvertTo(df, hn::PromoteTo(di, hn::LoadU(du, dst))),
                               hn::Set(df, 1.0f / 65535.0f));
      c = hn::Min(hn::Add(hn::Mul(old, keep), c), hn::Set(df, 1.0f));
    }
    hn::BlendedStore(hn::DemoteTo(du, unitToLanes(df, c)), pass16, du, dst);
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
  const auto passVec = hn::Set(di, static_cast<int32_t>(passBits));
  for (size_t i = 0; i < size_t(kBlockPixels); i += n) {
    auto pass = hn::RebindMask(df, hn::TestBit(passVec, hn::LoadU(di, kLaneBit + i)));
    if (cut) pass = hn::And(pass, hn::Gt(hn::LoadU(df, rgba[3] + i), hn::Zero(df)));
    if (hn::AllFalse(df, pass)) continue;
    // Translucent surfaces are seen through: they do not hide what is drawn after them.
    if (!blend) {
      const auto z = hn::Add(hn::Set(df, base[kDepth]), hn::LoadU(df, lanes.offset[kDepth] + i));
      hn::BlendedStore(z, pass, df, depth + i);
      // A pixel this triangle now owns no longer waits for a deferred one (shadeVisible).
      if (visible) {
        const hn::RebindToUnsigned<decltype(df)> du;
        hn::BlendedStore(hn::Set(du, kNoTriangle), hn::RebindMask(du, pass), du, visible + i);
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
  alignas(32) float base[8];
  blockBases(t, lanes, gx, gy, base);
  for (size_t i = 0; i < size_t(kBlockPixels); i += n) {
    const auto p0 = hn::LoadU(du32, pass[0] + i), p1 = hn::LoadU(du32, pass[1] + i);
    if (hn::AllTrue(du32, hn::Eq(hn::Or(p0, p1), hn::Zero(du32)))) continue;
    auto shown = hn::FirstN(df, n);  // all lanes
    if (cut) shown = hn::Gt(hn::LoadU(df, rgba[3] + i), hn::Zero(df));
    const auto zPix = hn::Add(hn::Set(df, base[kDepth]), hn::LoadU(df, lanes.offset[kDepth] + i));
    for (int s = 0; s < samples; ++s) {
      const auto passed = hn::And(
          shown, hn::RebindMask(df, hn::TestBit(s < 32 ? p0 : p1, hn::Set(du32, 1u << (s & 31)))));
      if (hn::AllFalse(df, passed)) continue;
      if (!blend)
        hn::BlendedStore(hn::Add(zPix, hn::Set(df, sampleDepth[s])), passed, df,
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

// Visibility (PixelOp::visibility): the depth test alone, recording triangle `id` in the pixels it
// wins — the SPEC §1 split of visibility from shading that the image generators of the seeds made
// in hardware: each pixel is shaded once, by its final winner, however many triangles covered it.
// Returns the pixels hidden by the depth test.
HWY_INLINE int visibleBlock(const TriangleSetup& t, const PlaneLanes& lanes, uint32_t mask, int gx,
                            int gy, uint32_t id, float* depth, uint32_t* visible) {
  const hn::CappedTag<float, kBlockPixels> df;
  const hn::RebindToSigned<decltype(df)> di;
  const hn::RebindToUnsigned<decltype(df)> du;
  const size_t n = hn::Lanes(df);
  alignas(32) float base[8];
  blockBases(t, lanes, gx, gy, base);
  const auto maskVec = hn::Set(di, static_cast<int32_t>(mask));
  const auto idVec = hn::Set(du, id);
  int hidden = 0;
  for (size_t i = 0; i < size_t(kBlockPixels); i += n) {
    const auto covered = hn::RebindMask(df, hn::TestBit(maskVec, hn::LoadU(di, kLaneBit + i)));
    if (hn::AllFalse(df, covered)) continue;
    const auto z = hn::Add(hn::Set(df, base[kDepth]), hn::LoadU(df, lanes.offset[kDepth] + i));
    const auto pass = hn::And(covered, hn::Lt(z, hn::LoadU(df, depth + i)));
    hidden += int(hn::CountTrue(df, covered) - hn::CountTrue(df, pass));
    hn::BlendedStore(z, pass, df, depth + i);
    hn::BlendedStore(idVec, hn::RebindMask(du, pass), du, visible + i);
  }
  return hidden;
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

// The occupancy view (TileWork::debugOccupancy): each pixel's red channel the log2 size of the
// largest full window holding it, 1 if only the pixel is occupied, 0 if nothing is.
void occupancyView(const Occupancy& occ, uint16_t* color) {
  for (int ly = 0; ly < kTileSize; ++ly)
    for (int lx = 0; lx < kTileSize; ++lx) {
      int level = 0;
      for (int l = Occupancy::kMaxLevel; l >= Occupancy::kMinLevel && !level; --l)
        if (occ.full(l, lx, ly)) level = l;
      if (!level) level = occ.pixels(lx, ly) >> ((ly & 3) * 4 + (lx & 3)) & 1;
      const size_t block = tileBlock(lx, ly);
      uint16_t* c = color + block * kColorPerBlock + (ly & 3) * kBlockSize + (lx & 3);
      c[0] = uint16_t(level);
      c[kBlockPixels] = c[2 * kBlockPixels] = 0;
    }
}

// Shades every pixel that records a triangle, with that triangle's planes and material (or its
// Gouraud colour), and clears the records. Pixels are batched by triangle, up to 16 to a batch
// from anywhere in the tile, so that a batch fills the SIMD lanes even for triangles of a few
// pixels (a batch per 4×4 block and triangle shaded 3 lanes for every pixel on tris 100k × 10
// px). A triangle's pixels are found in the blocks of its box (WinnerList), triangle after
// triangle; where the list is over its budget, by a scan of the tile, with open batches in a small
// table by triangle, a batch leaving it when full or when another triangle needs its slot. A
// pixel-shaded batch that leaves it short of 16 (on tris 100k × 10 px a batch held 7.2 pixels on
// average) has its attributes and texture coordinates evaluated and joins other triangles' pixels
// of its material in the mixer, which passes on whole batches. Pixel-shaded batches then wait in a
// queue, so that the texels each will read have been requested (shade::textureCoordinates) a whole
// queue's work earlier. A pixel's planes are evaluated at it directly, (c0 + dx·X) + dy·Y.
// docs/performance.md.
HWY_NOINLINE void shadeVisible(const TileContext& ctx) {
  const hn::CappedTag<float, kBlockPixels> df;
  const hn::RebindToSigned<decltype(df)> di;
  const hn::Rebind<uint16_t, decltype(df)> du16;
  const size_t n = hn::Lanes(df);
  // A pixel is named by its index in the tile's block-major layout (framebuffer.h): block·16 +
  // lane.
  struct Batch {
    uint32_t id = kNoTriangle;
    int count = 0;
    // Room for a whole vector appended past a count of up to 15 (the scan below).
    alignas(64) int32_t pixel[2 * kBlockPixels];
  };
  struct Queued {
    shade::Fragments fragments;
    shade::TexCoords coordinates;
    const shade::MaterialShading* material;
    int count;
    alignas(64) int32_t pixel[kBlockPixels];
  };
  // Pixels of one material from batches of fewer than 16 — triangles of a few pixels, or the
  // last pixels of larger ones — gathered with what shading needs of them (their attributes,
  // texture coordinates and levels of detail, each from its own triangle) until they fill a
  // queued batch, so that a 10-pixel triangle does not shade 16 lanes of its own. Room for 15
  // waiting lanes and a whole batch appended (an append writes 16 lanes).
  static constexpr int kMixLanes = 2 * kBlockPixels;
  struct Mixer {
    const shade::MaterialShading* material = nullptr;
    int count = 0;
    alignas(64) float q[kMixLanes];
    alignas(64) float color[kColorChannels][kMixLanes];
    alignas(64) float attribute[shade::kAttributeCount][kMixLanes];
    alignas(64) float lod[kMixLanes];
    alignas(64) float x0[kMixLanes];
    alignas(64) float y0[kMixLanes];
    alignas(64) int32_t pixel[kMixLanes];
  };
  // 256 open batches: a 64 × 64 tile of 10-pixel triangles holds about 400, and with 64 slots
  // their hash collisions emitted many batches half empty (256 slots: ×0.96 a frame on tris
  // 100k × 10 px textured; 512: no better).
  constexpr int kSlotBits = 8, kSlots = 1 << kSlotBits, kQueue = 32;
  Batch slots[kSlots];
  Queued queue[kQueue];
  int queued = 0;
  // (Zeroed: the vector mixer below reads its arrays whole, waiting lanes or not.)
  Mixer mix{};
  // Where a vector holds a whole batch, the mixer joins batches by turning lanes in registers;
  // through memory, lanes written at an offset and read back whole wait for those stores to retire
  // (store-to-load forwarding fails). Narrower vectors append through memory.
  constexpr bool kRotate = !HWY_HAVE_SCALABLE && hn::MaxLanes(df) == size_t(kBlockPixels);

  // (Highway's Iota builds its vector in memory, lane by lane: made once, not per block.)
  const auto laneIndex = hn::Iota(di, 0);
  // shade::attributesUsed of the material last asked about (batches run in long runs of one).
  const shade::MaterialShading* usedMaterial = nullptr;
  unsigned usedBits = 0;
  auto attributesOf = [&](const shade::MaterialShading* m) {
    if (m != usedMaterial) {
      usedMaterial = m;
      usedBits = shade::attributesUsed(*m, *ctx.environment);
    }
    return usedBits;
  };
  // Writes lanes [0, count) of 16-bit colour c16 to their pixels.
  auto store = [&](const int32_t* pixel, int count, const uint16_t(*c16)[kBlockPixels]) {
    // 16 lanes that are one block's pixels in order, whether one triangle's or several's: three
    // vector stores.
    bool block = count == kBlockPixels && (pixel[0] & (kBlockPixels - 1)) == 0 &&
                 pixel[kBlockPixels - 1] == pixel[0] + kBlockPixels - 1;
    for (size_t i = 0; block && i < size_t(kBlockPixels); i += n)
      block = hn::AllTrue(
          di, hn::Eq(hn::Load(di, pixel + i), hn::Add(laneIndex, hn::Set(di, pixel[0] + int(i)))));
    if (block) {
      uint16_t* dst = ctx.color + size_t(pixel[0] >> (2 * kBlockLog2)) * kColorPerBlock;
      for (int ch = 0; ch < kColorChannels; ++ch)
        for (size_t i = 0; i < size_t(kBlockPixels); i += n)
          hn::StoreU(hn::Load(du16, c16[ch] + i), du16, dst + ch * kBlockPixels + i);
      return;
    }
    for (int l = 0; l < count; ++l) {
      const int32_t p = pixel[l];
      uint16_t* dst = ctx.color + size_t(p >> (2 * kBlockLog2)) * kColorPerBlock +
                      size_t(p & (kBlockPixels - 1));
      for (int ch = 0; ch < kColorChannels; ++ch) dst[ch * kBlockPixels] = c16[ch][l];
    }
  };
  auto finishQueue = [&] {
    for (int e = 0; e < queued; ++e) {
      const Queued& q = queue[e];
      alignas(64) float rgba[4][kBlockPixels];
      shade::shadeFragments(*q.material, *ctx.environment, q.fragments, q.coordinates, rgba);
      alignas(64) uint16_t c16[kColorChannels][kBlockPixels];
      for (int ch = 0; ch < kColorChannels; ++ch)
        for (size_t i = 0; i < size_t(kBlockPixels); i += n)
          hn::Store(hn::DemoteTo(du16, unitToLanes(df, hn::Load(df, rgba[ch] + i))), du16,
                    c16[ch] + i);
      store(q.pixel, q.count, c16);
    }
    queued = 0;
  };
  auto enqueue = [&](const shade::MaterialShading* material, int count) {
    Queued& q = queue[queued];
    q.material = material;
    q.count = count;
    if (++queued == kQueue) finishQueue();
  };
  // Lanes [0, 16) of one of the mixer's arrays to `to` (lanes from `count` on repeat lane
  // count − 1), and, when more are waiting, lanes [16, 32) down to [0, 16).
  auto shipLanes = [&](float* from, float* to, int count, bool rest) {
    const auto last = hn::Set(df, from[count - 1]);
    for (size_t i = 0; i < size_t(kBlockPixels); i += n) {
      hn::Store(hn::IfThenElse(hn::FirstN(df, size_t(std::max(count - int(i), 0))),
                               hn::Load(df, from + i), last),
                df, to + i);
      if (rest) hn::Store(hn::Load(df, from + kBlockPixels + i), df, from + i);
    }
  };
  // Queues the mixer's first 16 lanes (or all it has) and moves the rest down.
  auto shipMix = [&] {
    const int count = std::min(mix.count, kBlockPixels);
    Queued& q = queue[queued];
    shade::Fragments& f = q.fragments;
    f.count = kBlockPixels;
    const bool rest = mix.count > kBlockPixels;
    const unsigned used = attributesOf(mix.material);
    shipLanes(mix.q, f.q, count, rest);
    for (int ch = 0; ch < kColorChannels; ++ch) shipLanes(mix.color[ch], f.color[ch], count, rest);
    for (int k = 0; k < shade::kAttributeCount; ++k)
      if (used & (1u << k)) shipLanes(mix.attribute[k], f.attribute[k], count, rest);
    if (mix.material->texture) {
      shipLanes(mix.lod, q.coordinates.lod, count, rest);
      shipLanes(mix.x0, q.coordinates.x0, count, rest);
      shipLanes(mix.y0, q.coordinates.y0, count, rest);
    }
    for (size_t i = 0; i < size_t(kBlockPixels); i += n) {
      hn::Store(hn::Load(di, mix.pixel + i), di, q.pixel + i);
      if (rest) hn::Store(hn::Load(di, mix.pixel + kBlockPixels + i), di, mix.pixel + i);
    }
    mix.count -= count;
    enqueue(mix.material, count);
  };
  // The attributes of batch b's pixels into f (material) or their Gouraud colour into c16; unused
  // lanes repeat the last pixel: valid positions, no extra texels.
  auto evaluate = [&](const Batch& b, shade::Fragments* f, uint16_t(*c16)[kBlockPixels]) {
    const TriangleSetup& t = ctx.setups[b.id];
    const AttributeSetup& a = ctx.attributes[b.id];
    const auto lastPixel = hn::Set(di, b.pixel[b.count - 1]);
    const unsigned used = f ? attributesOf(a.material) : 0;
    for (size_t i = 0; i < size_t(kBlockPixels); i += n) {
      const auto p = hn::IfThenElse(hn::FirstN(di, size_t(std::max(b.count - int(i), 0))),
                                    hn::Load(di, b.pixel + i), lastPixel);
      const auto block = hn::ShiftRight<2 * kBlockLog2>(p);
      const auto lane = hn::And(p, hn::Set(di, kBlockPixels - 1));
      const auto x =
          hn::Or(hn::ShiftLeft<kBlockLog2>(hn::And(block, hn::Set(di, kBlocksPerTileSide - 1))),
                 hn::And(lane, hn::Set(di, kBlockSize - 1)));
      const auto y = hn::Or(hn::ShiftLeft<kBlockLog2>(hn::ShiftRight<4>(block)),
                            hn::ShiftRight<kBlockLog2>(lane));
      static_assert(kBlocksPerTileSide == 16, "block row = block >> 4");
      const auto X = hn::ConvertTo(df, hn::Add(x, hn::Set(di, ctx.originX - t.minX)));
      const auto Y = hn::ConvertTo(df, hn::Add(y, hn::Set(di, ctx.originY - t.minY)));
      auto at = [&](const Plane& pl) {
        return hn::Add(hn::Add(hn::Set(df, pl.c0), hn::Mul(hn::Set(df, pl.dx), X)),
                       hn::Mul(hn::Set(df, pl.dy), Y));
      };
      const auto qv = at(t.invW);
      const Plane* color[kColorChannels] = {&t.red, &t.green, &t.blue};
      if (!f) {
        // shadeBlock's Gouraud colour.
        const auto w = hn::Div(hn::Set(df, 1.0f), qv);
        for (int ch = 0; ch < kColorChannels; ++ch)
          hn::Store(hn::DemoteTo(du16, colorToLanes(df, at(*color[ch]), w)), du16, c16[ch] + i);
        continue;
      }
      hn::Store(qv, df, f->q + i);
      const auto w = hn::Div(hn::Set(df, 1.0f), hn::Max(qv, hn::Set(df, 1e-30f)));
      for (int ch = 0; ch < kColorChannels; ++ch)
        hn::Store(hn::Min(hn::Max(hn::Mul(at(*color[ch]), w), hn::Zero(df)), hn::Set(df, 1.0f)), df,
                  f->color[ch] + i);
      for (int k = 0; k < shade::kAttributeCount; ++k)
        if (used & (1u << k)) hn::Store(at(a.planes[k]), df, f->attribute[k] + i);
    }
    if (f) {
      f->count = kBlockPixels;
      f->qdx = t.invW.dx;
      f->qdy = t.invW.dy;
      f->udx = a.planes[shade::kU].dx;
      f->udy = a.planes[shade::kU].dy;
      f->vdx = a.planes[shade::kV].dx;
      f->vdy = a.planes[shade::kV].dy;
    }
  };
  // The triangle of the last whole batch: a run of one triangle's whole blocks requests its
  // texels with its first block only. The blocks after it read texels next to those already read
  // (a block's box overlaps its neighbour's by about half); their requests cost more than the
  // misses they hid (tris 10k × 1000 px textured ×0.946, docs/performance.md).
  uint32_t requestedWhole = kNoTriangle;
  // Shades (Gouraud) or queues (material) batch b and empties it: a whole batch (or one to be
  // filtered anisotropically, which reads the triangle's gradients) as a queue entry of its own,
  // a partial one through the mixer. Texels are requested (shade::textureCoordinates) as the
  // batch is evaluated, one bounding box per batch (so a mixed batch's come in several; a whole
  // batch's only when it starts a run, above).
  auto emit = [&](Batch& b) {
    const shade::MaterialShading* material = ctx.attributes[b.id].material;
    if (!material) {
      alignas(64) uint16_t c16[kColorChannels][kBlockPixels];
      evaluate(b, nullptr, c16);
      store(b.pixel, b.count, c16);
    } else if (b.count == kBlockPixels || (material->texture && material->anisotropic)) {
      Queued& q = queue[queued];
      evaluate(b, &q.fragments, nullptr);
      if (material->texture)
        shade::textureCoordinates(*material, q.fragments, q.coordinates, b.id != requestedWhole);
      requestedWhole = b.id;
      std::copy_n(b.pixel, b.count, q.pixel);  // (store reads no further)
      enqueue(material, b.count);
    } else {
      shade::Fragments f;
      shade::TexCoords tc;
      evaluate(b, &f, nullptr);
      if (material->texture) shade::textureCoordinates(*material, f, tc);
      if (mix.count && mix.material != material) shipMix();
      mix.material = material;
      const unsigned used = attributesOf(material);
      if constexpr (kRotate) {
        // The batch turned by the mixer's count: its first lanes land after those waiting, and
        // the lanes that do not fit are then already at the start, where they wait in turn.
        const bool full = mix.count + b.count >= kBlockPixels;
        Queued& q = queue[queued];
        const auto keep = hn::FirstN(di, size_t(mix.count));
        const auto turn =
            hn::And(hn::Sub(laneIndex, hn::Set(di, mix.count)), hn::Set(di, kBlockPixels - 1));
        auto join = [&](auto d, const auto* from, auto* held, auto* to) {
          const auto r = hn::TableLookupLanes(hn::Load(d, from), hn::IndicesFromVec(d, turn));
          const auto c = hn::IfThenElse(hn::RebindMask(d, keep), hn::Load(d, held), r);
          if (full) hn::Store(c, d, to);
          hn::Store(full ? r : c, d, held);
        };
        join(df, f.q, mix.q, q.fragments.q);
        for (int ch = 0; ch < kColorChannels; ++ch)
          join(df, f.color[ch], mix.color[ch], q.fragments.color[ch]);
        for (int k = 0; k < shade::kAttributeCount; ++k)
          if (used & (1u << k))
            join(df, f.attribute[k], mix.attribute[k], q.fragments.attribute[k]);
        if (material->texture) {
          join(df, tc.lod, mix.lod, q.coordinates.lod);
          join(df, tc.x0, mix.x0, q.coordinates.x0);
          join(df, tc.y0, mix.y0, q.coordinates.y0);
        }
        join(di, b.pixel, mix.pixel, q.pixel);
        if (full) {
          q.fragments.count = kBlockPixels;
          mix.count += b.count - kBlockPixels;
          enqueue(material, kBlockPixels);
        } else {
          mix.count += b.count;
        }
      } else {
        auto append = [&](const float* from, float* to) {
          for (size_t i = 0; i < size_t(kBlockPixels); i += n)
            hn::StoreU(hn::Load(df, from + i), df, to + mix.count + i);
        };
        append(f.q, mix.q);
        for (int ch = 0; ch < kColorChannels; ++ch) append(f.color[ch], mix.color[ch]);
        for (int k = 0; k < shade::kAttributeCount; ++k)
          if (used & (1u << k)) append(f.attribute[k], mix.attribute[k]);
        if (material->texture) {
          append(tc.lod, mix.lod);
          append(tc.x0, mix.x0);
          append(tc.y0, mix.y0);
        }
        for (size_t i = 0; i < size_t(kBlockPixels); i += n)
          hn::StoreU(hn::Load(di, b.pixel + i), di, mix.pixel + mix.count + i);
        mix.count += b.count;
        if (mix.count >= kBlockPixels) shipMix();
      }
    }
    b.id = kNoTriangle;
    b.count = 0;
  };

  const hn::RebindToUnsigned<decltype(df)> du;
  const auto none = hn::Set(du, kNoTriangle);
  // Appends the lanes `mine` of `pixels` to triangle t's batch b, which leaves when full (the rest
  // start its next).
  auto take = [&](Batch& b, uint32_t t, auto pixels, auto mine) {
    hn::StoreU(hn::Compress(pixels, hn::RebindMask(di, mine)), di, b.pixel + b.count);
    b.count += int(hn::CountTrue(du, mine));
    if (b.count >= kBlockPixels) {
      const int rest = b.count - kBlockPixels;
      b.count = kBlockPixels;
      emit(b);
      std::copy_n(b.pixel + kBlockPixels, rest, b.pixel);
      b.id = t;
      b.count = rest;
    }
  };
  // Block `first`'s 16 pixels, all triangle t's, as a batch b by itself, lane for lane (store's
  // vector path), their records cleared; b is left open for t.
  auto takeWhole = [&](Batch& b, uint32_t t, int first) {
    for (size_t i = 0; i < size_t(kBlockPixels); i += n) {
      hn::StoreU(none, du, ctx.visible + first + i);
      hn::Store(hn::Add(laneIndex, hn::Set(di, first + int(i))), di, b.pixel + i);
    }
    b.id = t;
    b.count = kBlockPixels;
    emit(b);
    b.id = t;
  };
  WinnerList* list = ctx.winners;
  if (list && list->useful()) {
    ++ctx.stats->shadedByList;
    // Each triangle's blocks, in draw order (WinnerList): the pixels of a block that still record
    // the triangle are its own, taken by one compare and one compress; a block it holds whole is a
    // batch by itself, lane for lane (store's vector path). A batch's pixels stay in scan order.
    Batch b;
    for (int e = 0; e < list->count; ++e) {
      const WinnerList::Entry entry = list->entry[e];
      if (b.count) emit(b);
      b.id = entry.id;
      const auto id = hn::Set(du, entry.id);
      for (int by = entry.by0; by <= entry.by1; ++by)
        for (int bx = entry.bx0; bx <= entry.bx1; ++bx) {
          const int block = by * kBlocksPerTileSide + bx;
          uint32_t* visible = ctx.visible + block * kBlockPixels;
          const int first = block * kBlockPixels;
          bool whole = b.count == 0;
          for (size_t i = 0; whole && i < size_t(kBlockPixels); i += n)
            whole = hn::AllTrue(du, hn::Eq(hn::LoadU(du, visible + i), id));
          if (whole) {
            takeWhole(b, entry.id, first);
            continue;
          }
          for (size_t i = 0; i < size_t(kBlockPixels); i += n) {
            const auto mine = hn::Eq(hn::LoadU(du, visible + i), id);
            hn::BlendedStore(none, mine, du, visible + i);
            take(b, entry.id, hn::Add(laneIndex, hn::Set(di, first + int(i))), mine);
          }
        }
    }
    if (b.count) emit(b);
  } else {
    ++ctx.stats->shadedByScan;
    // Otherwise the tile's records a vector at a time: each triangle in a vector takes all its
    // pixels there at once (a compress of their numbers), so the work goes with the triangles a
    // block holds, not with its pixels. A batch's pixels stay in scan order.
    for (int start = 0; start < kTilePixels; start += int(n)) {
      uint32_t* visible = ctx.visible + start;
      if ((start & (kBlockPixels - 1)) == 0) {
        // A block one triangle holds whole (takeWhole).
        const uint32_t first = visible[0];
        bool whole = first != kNoTriangle;
        for (size_t i = 0; whole && i < size_t(kBlockPixels); i += n)
          whole = hn::AllTrue(du, hn::Eq(hn::LoadU(du, visible + i), hn::Set(du, first)));
        if (whole) {
          Batch b;
          takeWhole(b, first, start);
          start += kBlockPixels - int(n);
          continue;
        }
      }
      const auto ids = hn::LoadU(du, visible);
      auto left = hn::Ne(ids, none);
      if (hn::AllFalse(du, left)) continue;
      hn::StoreU(none, du, visible);
      alignas(64) uint32_t id[kBlockPixels];
      hn::Store(ids, du, id);
      const auto pixels = hn::Add(laneIndex, hn::Set(di, start));
      do {
        const uint32_t t = id[hn::FindKnownFirstTrue(du, left)];
        const auto mine = hn::And(left, hn::Eq(ids, hn::Set(du, t)));
        left = hn::AndNot(mine, left);
        Batch& b = slots[(t * 0x9E3779B1u) >> (32 - kSlotBits)];  // a multiplicative hash
        if (b.id != t) {
          if (b.count) emit(b);
          b.id = t;
        }
        take(b, t, pixels, mine);
      } while (!hn::AllFalse(du, left));
    }
    for (Batch& b : slots)
      if (b.count) emit(b);
  }
  if (list) list->reset();
  if (mix.count) shipMix();
  finishQueue();
}

// A bound of the triangle's depth over the pixels [gx0, gx1] × [gy0, gy1] (frame coordinates, with
// their squares when anti-aliased: samples lie within half a pixel of the centres): the smallest
// (upper = false) or largest value of its depth plane there, widened by more than the rounding of
// the kernel's own float evaluation. For hybrid masking's depth bounds.
HWY_INLINE float depthBound(const TriangleSetup& t, int gx0, int gy0, int gx1, int gy1, bool aa,
                            bool upper) {
  const double a = aa ? 0.5 : 0.0;
  const double x0 = gx0 - t.minX - a, x1 = gx1 - t.minX + a;
  const double y0 = gy0 - t.minY - a, y1 = gy1 - t.minY + a;
  const double dx = t.depth.dx, dy = t.depth.dy, c0 = t.depth.c0;
  const double margin =
      1e-6 * (1.0 + std::fabs(c0) + std::fabs(dx) * (std::fabs(x0) + std::fabs(x1)) +
              std::fabs(dy) * (std::fabs(y0) + std::fabs(y1)));
  if (upper) return float(c0 + std::max(dx * x0, dx * x1) + std::max(dy * y0, dy * y1) + margin);
  return float(c0 + std::min(dx * x0, dx * x1) + std::min(dy * y0, dy * y1) - margin);
}

// One triangle in one tile. T is the type edge values are stepped in: int64_t always works
// (geometry/setup.h's budget); int32_t is used for small triangles, whose values provably fit, and
// doubles the lanes per vector.
// kAA: anti-aliased (ctx.coverage set): pixel-square windows and sub-pixel masks in the leaves.
template <int E, PixelOp kOp, class T, bool kAA = false>
class TriangleRaster {
 public:
  TriangleRaster(const TriangleSetup& t, const TileContext& ctx,
                 const AttributeSetup* attributes = nullptr, uint32_t id = kNoTriangle)
      : t_(t), ctx_(ctx), attributes_(attributes), id_(id) {
    // Priority masking: opaque triangles are dropped where nearer ones occupy the tile and mark
    // what they cover; cut-outs (alpha mask) are dropped but mark nothing (their holes show what
    // lies behind); translucent ones blend over whatever the depth test lets through.
    if constexpr (kOp != PixelOp::overdraw) {
      const shade::AlphaUse alpha = attributes && attributes->material ? attributes->material->alpha
                                                                       : shade::AlphaUse::opaque;
      if (alpha != shade::AlphaUse::blend) occ_ = ctx.occupancy;
      mark_ = occ_ && alpha == shade::AlphaUse::opaque;
      computePlaneLanes(t, planeLanes_);
    }
    if constexpr (kOp == PixelOp::material) computeAttributeLanes(*attributes, attributeLanes_);
    if constexpr (kAA) setUpSamples();
    for (int k = 0; k < E; ++k) {
      const auto& e = t.edges[k];
      sX_[k] = T(e.stepX());
      sY_[k] = T(e.stepY());
      pos_[k] = std::max<T>(sX_[k], 0) + std::max<T>(sY_[k], 0);
      neg_[k] = std::min<T>(sX_[k], 0) + std::min<T>(sY_[k], 0);
      // e at the 16 pixel centres of a block, relative to its top-left one: sX·lx + sY·ly.
      if constexpr (sizeof(T) == 4) {
        const hn::CappedTag<T, kBlockPixels> d;
        for (size_t i = 0; i < size_t(kBlockPixels); i += hn::Lanes(d)) {
          const auto lx = hn::LoadU(d, kLaneX + i), ly = hn::LoadU(d, kLaneY + i);
          hn::StoreU(hn::Add(hn::Mul(lx, hn::Set(d, sX_[k])), hn::Mul(ly, hn::Set(d, sY_[k]))), d,
                     leafOffset_[k] + i);
        }
      } else {
        for (int i = 0; i < kBlockPixels; ++i)
          leafOffset_[k][i] = sX_[k] * T(kLaneX[i]) + sY_[k] * T(kLaneY[i]);
      }
    }
  }

  // Draws the part of the triangle inside the tile.
  void draw() {
    // Step 1: the bounding box inside the tile, in tile-local pixels.
    const int x0 = std::max(t_.minX - ctx_.originX, 0);
    const int y0 = std::max(t_.minY - ctx_.originY, 0);
    const int x1 = std::min(t_.maxX - ctx_.originX, kTileSize - 1);
    const int y1 = std::min(t_.maxY - ctx_.originY, kTileSize - 1);
    if (x0 > x1 || y0 > y1) return;
    boxX0_ = x0;
    boxY0_ = y0;
    boxX1_ = x1;
    boxY1_ = y1;
    if (occ_ && ctx_.hybrid)
      boxZmin_ = depthBound(t_, ctx_.originX + x0, ctx_.originY + y0, ctx_.originX + x1,
                            ctx_.originY + y1, kAA, false);
    // Step 2: start the descent at the aligned cell size that matches the triangle's extent (SPEC
    // §3 allows any initial window): half the extent rounded up to a power of two, so the box
    // spans at most 3×3 cells — instead of descending from the whole screen (RASTER-NOTES: 3–7×
    // slower for small triangles). Up to kScanExtent pixels the cells are the 4×4 leaves
    // themselves: a scan of the box's blocks, each tested in SIMD, beats any descent there.
    // Measured, 1 thread, 1920×1080 (docs/performance.md): tris of 100 px² 24.2 → 20.4 ms and of
    // 300 px² 16.0 → 14.5 ms with the scan up to 32 px; of 3000 px² 18.0 → 19.4 ms up to 48 px.
    constexpr int kScanExtent = 32;
    const int extent = std::max(x1 - x0, y1 - y0) + 1;
    const int log2n = extent <= kScanExtent
                          ? kBlockLog2
                          : std::max(kBlockLog2, int(std::bit_width(unsigned(extent - 1))) - 1);
    const int n = 1 << log2n;
    for (int cy = y0 >> log2n; cy <= y1 >> log2n; ++cy)
      for (int cx = x0 >> log2n; cx <= x1 >> log2n; ++cx)
        visitRoot(cx << log2n, cy << log2n, log2n, n);
    if constexpr (kAA && kOp == PixelOp::material) flushSamples();
  }

 private:
  static int statLevel(int log2n) { return kTileLog2 - log2n; }

  // Over a window of m + 1 pixels a side whose top-left value is tl, tl + maxOffset(k, m) < 0 iff
  // the window lies wholly outside edge k, and tl + minOffset(k, m) ≥ 0 iff wholly inside: the
  // extreme pixel centre, and with anti-aliasing its square (the constants above).
  T maxOffset(int k, T m) const {
    if constexpr (kAA) return pos_[k] * m + rejectOffset_[k];
    return pos_[k] * m;
  }
  T minOffset(int k, T m) const {
    if constexpr (kAA) return neg_[k] * m + acceptOffset_[k];
    return neg_[k] * m;
  }

  // Anti-aliasing, per triangle: per edge the mask-table row, the aperture constants and the
  // divisor S of the distance cell; per sample the depth offset from the pixel centre.
  void setUpSamples() {
    const CoverageTables& cov = *ctx_.coverage;
    for (int k = 0; k < E; ++k) {
      const int64_t a = t_.edges[k].a, b = t_.edges[k].b;
      const bool owns = a > 0 || (a == 0 && b > 0);  // setup.cpp's fill rule, taken back out
      const int64_t S = std::abs(a) + std::abs(b);
      const int64_t bias = owns ? 0 : 1, half = 128 * S;
      rejectOffset_[k] = T(bias + half - 1);
      acceptOffset_[k] = T(bias - half);
      bias_[k] = T(bias);
      int row = EdgeMaskTable::kConstantRow;
      if (S != 0) {
        const int quadrant = int(a < 0 || (a == 0 && b < 0)) | int(b < 0 || (b == 0 && a < 0)) << 1;
        // ⌊32·|a| / S⌋ in double: the correctly rounded quotient of integers below 2^53 floors
        // exactly (as EdgeMaskTable::mask's), and costs a fraction of an int64 division.
        const double slope =
            std::floor(double(EdgeMaskTable::kSlopeSteps) * double(std::abs(a)) / double(S));
        row =
            EdgeMaskTable::rowIndex(quadrant, std::min(EdgeMaskTable::kSlopeSteps - 1, int(slope)));
      }
      rowOffset_[k] = row * EdgeMaskTable::kRowEntries;
      divisor_[k] = int32_t(std::max<int64_t>(S, 1));  // S < 2^25 (setup.h budget)
      reciprocal_[k] = 1.0f / float(divisor_[k]);
    }
    const auto& offsets = cov.pattern->offsets;
    sampleDepthMax_ = -std::numeric_limits<float>::infinity();
    for (int s = 0; s < cov.samples; ++s) {
      sampleDepth_[s] =
          t_.depth.dx * float(offsets[size_t(s)][0]) + t_.depth.dy * float(offsets[size_t(s)][1]);
      sampleDepthMax_ = std::max(sampleDepthMax_, sampleDepth_[s]);
    }
  }

  // Classifies a root window by the coverage function of each edge, then fills, tests or splits.
  void visitRoot(int lx, int ly, int log2n, int n) {
    ++ctx_.stats->windows[statLevel(log2n)];
    if (occ_ && hidden(log2n, lx, ly, true)) {
      ++ctx_.stats->occludedWindows;
      return;
    }
    T tl[kMaxEdges];
    for (int k = 0; k < E; ++k) {
      const auto& e = t_.edges[k];
      tl[k] = T(e.c + e.stepX() * (ctx_.originX + lx) + e.stepY() * (ctx_.originY + ly));
    }
    // A root that is already a leaf: its SIMD test decides everything, skip the classification.
    if (log2n == kBlockLog2) return leaf(lx, ly, tl, (1u << E) - 1);
    unsigned active = 0;
    for (int k = 0; k < E; ++k) {
      if (tl[k] + maxOffset(k, T(n - 1)) < 0) return;             // d < 0: outside
      if (tl[k] + minOffset(k, T(n - 1)) < 0) active |= 1u << k;  // d < 2ε: the edge crosses
    }
    descend(lx, ly, log2n, tl, active);
  }

  void descend(int lx, int ly, int log2n, const T* tl, unsigned active) {
    if (active == 0) return fill(lx, ly, 1 << log2n);
    if (log2n == kBlockLog2) return leaf(lx, ly, tl, active);
    split(lx, ly, log2n, tl, active);
  }

  // SPEC §3.5: the four children of a window are tested together, one SIMD lane per child.
  void split(int lx, int ly, int log2n, const T* tl, unsigned active) {
    const int hLog2 = log2n - 1;
    const T h = T(1) << hLog2;
    const hn::CappedTag<T, 4> d;
    const size_t lanes = hn::Lanes(d);
    const auto zero = hn::Zero(d), minusOne = hn::Set(d, T(-1));  // x ≥ 0 ⇔ x > −1 on integers
    alignas(32) T childTl[kMaxEdges][4];
    unsigned rejected = 0;
    unsigned accepted[kMaxEdges] = {};
    for (int k = 0; k < E; ++k) {
      if (!(active & (1u << k))) continue;
      const auto stepX = hn::Set(d, sX_[k] * h), stepY = hn::Set(d, sY_[k] * h);
      const auto base = hn::Set(d, tl[k]);
      const auto dMax = hn::Set(d, maxOffset(k, h - 1));
      const auto dMin = hn::Set(d, minOffset(k, h - 1));
      for (size_t i = 0; i < 4; i += lanes) {
        // The children's offsets {0, sX·h, sY·h, (sX + sY)·h}, built from constant lane masks:
        // filled in a local array with scalar stores and read back as a vector, they stalled on
        // store forwarding (perf: a third of split's time on tris 10k × 1000 px).
        const auto ctl = hn::Add(base, hn::Add(hn::And(hn::LoadU(d, kChildMaskX<T> + i), stepX),
                                               hn::And(hn::LoadU(d, kChildMaskY<T> + i), stepY)));
        hn::StoreU(ctl, d, childTl[k] + i);
        uint8_t out = 0, in = 0;
        hn::StoreMaskBits(d, hn::Lt(hn::Add(ctl, dMax), zero), &out);
        hn::StoreMaskBits(d, hn::Gt(hn::Add(ctl, dMin), minusOne), &in);
        rejected |= unsigned(out) << i;
        accepted[k] |= unsigned(in) << i;
      }
    }
    ctx_.stats->windows[statLevel(hLog2)] += 4;
    for (unsigned live = ~rejected & 0xFu; live; live &= live - 1) {
      const int c = std::countr_zero(live);
      if (occ_ && hidden(hLog2, lx + (c & 1) * int(h), ly + (c >> 1) * int(h), false)) {
        ++ctx_.stats->occludedWindows;
        continue;
      }
      unsigned childActive = active;
      T ctl[kMaxEdges] = {};
      for (int k = 0; k < E; ++k) {
        if (!(active & (1u << k))) continue;
        if (accepted[k] & (1u << c)) childActive &= ~(1u << k);
        ctl[k] = childTl[k][c];
      }
      descend(lx + (c & 1) * int(h), ly + (c >> 1) * int(h), hLog2, ctl, childActive);
    }
  }

  // A 4×4 leaf crossed by the `active` edges: the last two levels of the subdivision unrolled —
  // all 16 pixel centres tested at once in SIMD lanes.
  void leaf(int lx, int ly, const T* tl, unsigned active) {
    if constexpr (kAA) return leafSamples(lx, ly, tl, active);
    const hn::CappedTag<T, kBlockPixels> d;
    const size_t lanes = hn::Lanes(d);
    const auto minusOne = hn::Set(d, T(-1));
    uint32_t mask = 0;
    for (size_t i = 0; i < size_t(kBlockPixels); i += lanes) {
      auto inside = hn::FirstN(d, lanes);
      for (int k = 0; k < E; ++k) {
        if (!(active & (1u << k))) continue;
        const auto e = hn::Add(hn::Set(d, tl[k]), hn::LoadU(d, leafOffset_[k] + i));
        inside = hn::And(inside, hn::Gt(e, minusOne));
      }
      mask |= laneBits(d, inside, i);
    }
    ++ctx_.stats->partialBlocks;
    ctx_.stats->windows[kStatLevels - 1] += kBlockPixels;
    if (occ_ && !ctx_.hybrid) mask &= ~occ_->pixels(lx, ly);
    if (!mask) return;
    drawLevel_ = 1;
    shade(lx, ly, mask);
    if (mark_) occ_->addPixels(lx, ly, mask, blockDepth(lx, ly));
  }

  // An anti-aliased leaf: per pixel, the AND of the crossing edges' masks from the table.
  void leafSamples(int lx, int ly, const T* tl, unsigned active) {
    ++ctx_.stats->partialBlocks;
    ctx_.stats->windows[kStatLevels - 1] += kBlockPixels;
    // The block's own coverage test first (roots of the 4×4 scan come here untested): an edge
    // that misses every pixel square ends the leaf, one that covers them all needs no look-up.
    for (int k = 0; k < E; ++k) {
      if (!(active & (1u << k))) continue;
      if (tl[k] + maxOffset(k, T(kBlockSize - 1)) < 0) return;
      if (tl[k] + minOffset(k, T(kBlockSize - 1)) >= 0) active &= ~(1u << k);
    }
    if (active == 0) return fillBlock(lx, ly);
    const hn::CappedTag<int32_t, kBlockPixels> di;
    const hn::Rebind<float, decltype(di)> df;
    const size_t lanes = hn::Lanes(di);
    const CoverageTables& cov = *ctx_.coverage;
    // The distance cell q = ⌊|E|·D / N1⌋ = ⌊(|E| >> kShift) / S⌋ for D = kDistanceSteps cells
    // (N1 = 256·S; nested floors of positive integers compose), capped at D/2 (|d| ≥ ½).
    constexpr int kHalf = EdgeMaskTable::kDistanceSteps / 2;
    constexpr int kShift = 8 - std::countr_zero(unsigned(EdgeMaskTable::kDistanceSteps));
    static_assert(EdgeMaskTable::kDistanceSteps << kShift == 256, "D divides 256");
    // int64 edges: the cell and the side per pixel in scalar code first (the large triangles'
    // leaves); int32 edges go straight from the vector below. The same estimate-and-correct
    // division as there, in double and int64 (a ≤ (D/2)·S < 2^32).
    alignas(64) int32_t cell[E][kBlockPixels], positive[E][kBlockPixels];
    if constexpr (sizeof(T) == 8) {
      for (int k = 0; k < E; ++k) {
        if (!(active & (1u << k))) continue;
        const T S = divisor_[k];
        const double reciprocal = 1.0 / double(S);
        for (int p = 0; p < kBlockPixels; ++p) {
          const T e = tl[k] + leafOffset_[k][p];
          const T geometric = e + bias_[k];
          positive[k][p] = e >= 0 ? -1 : 0;
          const T a = std::min<T>((geometric < 0 ? -geometric : geometric) >> kShift, kHalf * S);
          T q = T(double(a) * reciprocal);
          const T r = a - q * S;
          q += (r >= S) - (r < 0);
          cell[k][p] = int32_t(q);
        }
      }
    }
    // Row entries are read by vector gathers: scalar loads of SIMD-computed entries measured 7 %
    // slower (AMD Zen 4, 100k triangles of 10 px at 4 samples: 28.1 vs 26.3 ms).
    alignas(64) uint32_t masks[2][kBlockPixels], coverage[2][kBlockPixels];
    const uint32_t(*occupied)[kBlockPixels] =
        occ_ && !ctx_.hybrid ? occ_->samples(lx, ly) : nullptr;
    const auto zero = hn::Zero(di), minusOne = hn::Set(di, -1);
    const int32_t* word0 = reinterpret_cast<const int32_t*>(cov.word[0].data());
    const int32_t* word1 = reinterpret_cast<const int32_t*>(cov.word[1].data());
    int covered = 0;
    // Pixels outside the triangle's box get nothing: near a vertex the AND of area masks can claim
    // samples beyond the triangle (coverage_masks.h); the box — the pixel squares the triangle
    // reaches — bounds them, as it bounds the traversal.
    const int gx = ctx_.originX + lx, gy = ctx_.originY + ly;
    const bool clipToBox = gx < t_.minX || gx + kBlockSize - 1 > t_.maxX || gy < t_.minY ||
                           gy + kBlockSize - 1 > t_.maxY;
    for (size_t i = 0; i < size_t(kBlockPixels); i += lanes) {
      auto m0 = hn::Set(di, -1), m1 = m0;
      if (clipToBox) {
        const auto x = hn::Add(hn::Set(di, gx), hn::LoadU(di, kLaneX + i));
        const auto y = hn::Add(hn::Set(di, gy), hn::LoadU(di, kLaneY + i));
        const auto inBox = hn::And(
            hn::And(hn::Gt(x, hn::Set(di, t_.minX - 1)), hn::Lt(x, hn::Set(di, t_.maxX + 1))),
            hn::And(hn::Gt(y, hn::Set(di, t_.minY - 1)), hn::Lt(y, hn::Set(di, t_.maxY + 1))));
        m0 = m1 = hn::VecFromMask(di, inBox);
      }
      for (int k = 0; k < E; ++k) {
        if (!(active & (1u << k))) continue;
        hn::Vec<decltype(di)> q;
        hn::Mask<decltype(di)> inside;  // e ≥ 0: the side of the edge the cell index counts up
        if constexpr (sizeof(T) == 4) {
          const auto S = hn::Set(di, divisor_[k]);
          const auto e = hn::Add(hn::Set(di, tl[k]), hn::LoadU(di, leafOffset_[k] + i));
          inside = hn::Gt(e, minusOne);
          // a ≤ (D/2)·S < 2^23 (small triangles: S < 2^16), so a / S ≤ D/2: the float estimate
          // rounded to an integer by the magic number 2^23 (cheaper than a checked conversion)
          // is within one of ⌊a / S⌋, then corrected exactly.
          const auto a = hn::Min(hn::ShiftRight<kShift>(hn::Abs(hn::Add(e, hn::Set(di, bias_[k])))),
                                 hn::Set(di, kHalf * divisor_[k]));
          q = hn::Sub(
              hn::BitCast(di, hn::Add(hn::Mul(hn::ConvertTo(df, a), hn::Set(df, reciprocal_[k])),
                                      hn::Set(df, 8388608.0f))),
              hn::Set(di, 0x4B000000));  // the bits of 2^23
          const auto r = hn::Sub(a, hn::Mul(q, S));
          q = hn::Add(q, hn::VecFromMask(di, hn::Lt(r, zero)));                        // − 1
          q = hn::Sub(q, hn::VecFromMask(di, hn::Gt(r, hn::Sub(S, hn::Set(di, 1)))));  // + 1
        } else {
          inside = hn::Lt(hn::LoadU(di, positive[k] + i), zero);
          q = hn::LoadU(di, cell[k] + i);
        }
        // Row entry: 1 + (D/2 + q) on the inside, 1 + (D/2 − 1 − q) mirrored
        // (EdgeMaskTable::mask).
        const auto idx = hn::IfThenElse(inside, hn::Add(q, hn::Set(di, rowOffset_[k] + kHalf + 1)),
                                        hn::Sub(hn::Set(di, rowOffset_[k] + kHalf), q));
        m0 = hn::And(m0, hn::GatherIndex(di, word0, idx));
        if (cov.words == 2) m1 = hn::And(m1, hn::GatherIndex(di, word1, idx));
      }
      if (cov.words == 1) m1 = zero;
      if (occupied) {  // the samples nearer primitives hold are not this one's
        hn::StoreU(m0, di, reinterpret_cast<int32_t*>(coverage[0] + i));
        hn::StoreU(m1, di, reinterpret_cast<int32_t*>(coverage[1] + i));
        m0 = hn::AndNot(hn::LoadU(di, reinterpret_cast<const int32_t*>(occupied[0] + i)), m0);
        m1 = hn::AndNot(hn::LoadU(di, reinterpret_cast<const int32_t*>(occupied[1] + i)), m1);
      }
      hn::StoreU(m0, di, reinterpret_cast<int32_t*>(masks[0] + i));
      hn::StoreU(m1, di, reinterpret_cast<int32_t*>(masks[1] + i));
      covered += int(hn::CountTrue(di, hn::Ne(hn::Or(m0, m1), zero)));
    }
    if (!covered) return;
    shadeSamples(lx, ly, masks, covered, occupied ? coverage : nullptr);
    if (mark_) markOrDefer(lx, ly, masks);
  }

  // Hybrid masking reads a block's depth when it becomes full: a block whose samples are still
  // queued for shading (queueSamples) is marked once they are written (flushSamples).
  void markOrDefer(int lx, int ly, const uint32_t (*masks)[kBlockPixels]) {
    if constexpr (kAA && kOp == PixelOp::material) {
      if (ctx_.hybrid && pendingBlocks_ > 0 && pending_[pendingBlocks_ - 1].lx == lx &&
          pending_[pendingBlocks_ - 1].ly == ly) {
        PendingBlock& b = pending_[pendingBlocks_ - 1];
        std::copy_n(masks[0], kBlockPixels, b.marks[0]);
        std::copy_n(masks[1], kBlockPixels, b.marks[1]);
        b.markAfter = true;
        return;
      }
    }
    markSamples(lx, ly, masks);
  }

  // Occupies the samples `masks` holds in the block at (lx, ly) (Occupancy::addSamples in SIMD
  // lanes); with depth (hybrid), a block that becomes full gets the largest depth of its samples.
  void markSamples(int lx, int ly, const uint32_t (*masks)[kBlockPixels]) {
    if (occ_->full(kBlockLog2, lx, ly)) return;
    uint32_t(*words)[kBlockPixels] = occ_->sampleWords(lx, ly);
    const hn::CappedTag<uint32_t, kBlockPixels> du;
    const size_t lanes = hn::Lanes(du);
    const auto full0 = hn::Set(du, occ_->fullWords()[0]), full1 = hn::Set(du, occ_->fullWords()[1]);
    uint32_t pixels = 0;
    for (size_t i = 0; i < size_t(kBlockPixels); i += lanes) {
      const auto w0 = hn::Or(hn::LoadU(du, words[0] + i), hn::LoadU(du, masks[0] + i));
      const auto w1 = hn::Or(hn::LoadU(du, words[1] + i), hn::LoadU(du, masks[1] + i));
      hn::StoreU(w0, du, words[0] + i);
      hn::StoreU(w1, du, words[1] + i);
      pixels |= laneBits(du, hn::And(hn::Eq(w0, full0), hn::Eq(w1, full1)), i);
    }
    occ_->setPixels(lx, ly, pixels, pixels == 0xFFFF ? blockZmax(lx, ly) : Occupancy::kNoBound);
  }

  // The largest depth in the block's sample planes (hybrid), +∞ for priority masking.
  float blockZmax(int lx, int ly) const {
    const float* depth = blockDepth(lx, ly);
    if (!depth) return Occupancy::kNoBound;
    const hn::ScalableTag<float> df;
    auto m = hn::Set(df, -Occupancy::kNoBound);
    const size_t n = size_t(ctx_.samples) * kBlockPixels;  // a multiple of 16
    for (size_t i = 0; i < n; i += hn::Lanes(df)) m = hn::Max(m, hn::LoadU(df, depth + i));
    return hn::GetLane(hn::MaxOfLanes(df, m));
  }

  void fill(int lx, int ly, int n) {
    if (occ_) return fillMasked(lx, ly, std::countr_zero(unsigned(n)));
    plainFill(lx, ly, n);
  }

  // A covered window under priority masking: occupied parts dropped, empty parts filled directly,
  // and the window occupied afterwards.
  void fillMasked(int lx, int ly, int level) {
    if (hidden(level, lx, ly, false)) {
      ++ctx_.stats->occludedWindows;
      return;
    }
    if (!occ_->touched(level, lx, ly)) {
      plainFill(lx, ly, 1 << level);
      if (mark_) occ_->markFull(level, lx, ly, windowZmax(level, lx, ly));
      return;
    }
    if (level == kBlockLog2) return fillBlock(lx, ly);
    const int h = 1 << (level - 1);
    for (int c = 0; c < 4; ++c) fillMasked(lx + (c & 1) * h, ly + (c >> 1) * h, level - 1);
  }

  // A 4×4 block wholly inside the triangle: its free pixels (samples) only, under masking.
  void fillBlock(int lx, int ly) {
    if (!occ_) return plainFill(lx, ly, kBlockSize);
    if (ctx_.hybrid) {
      // Every sample drawn (where it passes): a block that was full keeps the smaller bound, one
      // that becomes full reads its exact bound from the depth buffer.
      const bool wasFull = occ_->full(kBlockLog2, lx, ly);
      plainFill(lx, ly, kBlockSize);
      if (!mark_) return;
      if (wasFull) return occ_->lowerZmax(kBlockLog2, lx, ly, windowZmax(kBlockLog2, lx, ly));
      if constexpr (kAA) {
        alignas(64) uint32_t all[2][kBlockPixels];
        std::fill_n(all[0], kBlockPixels, occ_->fullWords()[0]);
        std::fill_n(all[1], kBlockPixels, occ_->fullWords()[1]);
        markOrDefer(lx, ly, all);
      } else {
        occ_->sampleWords(lx, ly);  // touched
        occ_->setPixels(lx, ly, 0xFFFF, blockZmax(lx, ly));
      }
      return;
    }
    if constexpr (kAA) {
      alignas(64) uint32_t masks[2][kBlockPixels] = {}, all[2][kBlockPixels];
      if (const auto* held = occ_->samples(lx, ly)) std::memcpy(masks, held, sizeof(masks));
      const uint32_t fullWord0 = fullSampleWord(ctx_.samples, 0);
      const uint32_t fullWord1 = fullSampleWord(ctx_.samples, 1);
      int covered = 0;
      for (int p = 0; p < kBlockPixels; ++p) {
        masks[0][p] = fullWord0 & ~masks[0][p];
        masks[1][p] = fullWord1 & ~masks[1][p];
        all[0][p] = fullWord0;
        all[1][p] = fullWord1;
        covered += (masks[0][p] | masks[1][p]) != 0;
      }
      if (!covered) return;
      ++ctx_.stats->fullWindows;
      shadeSamples(lx, ly, masks, covered, all);  // shaded at the centres, as when unoccupied
      if (mark_) markSamples(lx, ly, masks);
    } else {
      const uint32_t mask = 0xFFFFu & ~occ_->pixels(lx, ly);
      if (!mask) return;
      ++ctx_.stats->fullWindows;
      drawLevel_ = kBlockLog2;
      shade(lx, ly, mask);
      if (mark_) occ_->addPixels(lx, ly, mask);
    }
  }

  // Whether masking drops the window of size 2^level at (lx, ly): occupied (priority; for a root
  // window, inside an occupied one), or full with a depth bound the triangle does not beat in the
  // window's part of its box (hybrid).
  bool hidden(int level, int lx, int ly, bool root) const {
    if (!ctx_.hybrid) return root ? occ_->fullOrInside(level, lx, ly) : occ_->full(level, lx, ly);
    const float bound = occ_->zmaxOver(level, lx, ly);
    if (bound == Occupancy::kNoBound) return false;
    // Small windows are judged by the triangle's smallest depth in its whole box (one bound per
    // triangle: per-window bounds for every 4×4 root of a small triangle cost more than they cull).
    if (boxZmin_ >= bound) return true;
    if (level <= 3) return false;
    const int n = 1 << level;
    return depthBound(t_, ctx_.originX + std::max(lx, boxX0_), ctx_.originY + std::max(ly, boxY0_),
                      ctx_.originX + std::min(lx + n - 1, boxX1_),
                      ctx_.originY + std::min(ly + n - 1, boxY1_), kAA, false) >= bound;
  }
  // The triangle's largest depth over a window it covers (hybrid); +∞ for priority masking.
  float windowZmax(int level, int lx, int ly) const {
    if (!ctx_.hybrid) return Occupancy::kNoBound;
    const int n = 1 << level;
    return depthBound(t_, ctx_.originX + lx, ctx_.originY + ly, ctx_.originX + lx + n - 1,
                      ctx_.originY + ly + n - 1, kAA, true);
  }
  // The block's depth buffer (all its sample planes), for the exact bound of a block that becomes
  // full (hybrid); nullptr for priority masking.
  const float* blockDepth(int lx, int ly) const {
    if (!ctx_.hybrid) return nullptr;
    const size_t block = tileBlock(lx, ly);
    return ctx_.depth + block * size_t(ctx_.samples) * kBlockPixels;
  }

  void plainFill(int lx, int ly, int n) {
    ++ctx_.stats->fullWindows;
    drawLevel_ = std::countr_zero(unsigned(n));
    for (int by = ly; by < ly + n; by += kBlockSize)
      for (int bx = lx; bx < lx + n; bx += kBlockSize) {
        if constexpr (kAA)
          shadeSamples(bx, by, nullptr, kBlockPixels);
        else
          shade(bx, by, 0xFFFF);
      }
  }

  void shade(int lx, int ly, uint32_t mask) {
    ctx_.stats->fragments += std::popcount(mask);
    const size_t block = tileBlock(lx, ly);
    if constexpr (kOp == PixelOp::overdraw) {
      countBlock(mask, ctx_.color + block * kColorPerBlock);
    } else if constexpr (kOp == PixelOp::levels) {
      ctx_.stats->hiddenFragments +=
          levelBlock(t_, planeLanes_, mask, ctx_.originX + lx, ctx_.originY + ly, drawLevel_,
                     ctx_.depth + block * kBlockPixels, ctx_.color + block * kColorPerBlock);
    } else if constexpr (kOp == PixelOp::visibility) {
      ctx_.stats->hiddenFragments +=
          visibleBlock(t_, planeLanes_, mask, ctx_.originX + lx, ctx_.originY + ly, id_,
                       ctx_.depth + block * kBlockPixels, ctx_.visible + block * kBlockPixels);
    } else if constexpr (kOp == PixelOp::material) {
      ctx_.stats->hiddenFragments +=
          shadeBlockMaterial(t_, planeLanes_, attributeLanes_, *attributes_, *ctx_.environment,
                             mask, ctx_.originX + lx, ctx_.originY + ly,
                             ctx_.depth + block * kBlockPixels, ctx_.color + block * kColorPerBlock,
                             ctx_.visible ? ctx_.visible + block * kBlockPixels : nullptr);
    } else {
      ctx_.stats->hiddenFragments +=
          shadeBlock(t_, planeLanes_, mask, ctx_.originX + lx, ctx_.originY + ly,
                     ctx_.depth + block * kBlockPixels, ctx_.color + block * kColorPerBlock);
    }
  }

  // `shading`: as shadeBlockSamples.
  void shadeSamples(int lx, int ly, const uint32_t (*masks)[kBlockPixels], int pixels,
                    const uint32_t (*shading)[kBlockPixels] = nullptr) {
    ctx_.stats->fragments += uint64_t(pixels);
    const size_t block = tileBlock(lx, ly);
    const size_t planes = block * size_t(ctx_.samples);
    if constexpr (kOp == PixelOp::material) return queueSamples(lx, ly, masks, shading);
    ctx_.stats->hiddenFragments += shadeBlockSamples(
        t_, planeLanes_, *ctx_.coverage, sampleDepth_, masks, ctx_.originX + lx, ctx_.originY + ly,
        blockDepthOrClear(planes), ctx_.color + planes * kColorPerBlock, shading, blockSums(block),
        ctx_.clearColor);
  }

  // Colour sums (TileWork::sums): block `block`'s, or nullptr; and the depth its samples are
  // tested against — the tile's planes, or with sums the clear depth (all an unwritten sample
  // holds).
  int32_t* blockSums(size_t block) const {
    return ctx_.sums ? ctx_.sums + block * kColorPerBlock : nullptr;
  }
  float* blockDepthOrClear(size_t planes) const {
    return ctx_.sums ? ctx_.clearPlanes : ctx_.depth + planes * kBlockPixels;
  }

  // Anti-aliased pixel shading (PixelOp::material): step 1 for the block at (lx, ly), its passing
  // pixels queued for step 2.
  void queueSamples(int lx, int ly, const uint32_t (*masks)[kBlockPixels],
                    const uint32_t (*shading)[kBlockPixels] = nullptr) {
    const size_t block = tileBlock(lx, ly);
    const size_t planes = block * size_t(ctx_.samples);
    PendingBlock& b = pending_[pendingBlocks_];
    alignas(64) float cx[kBlockPixels], cy[kBlockPixels];
    const int gx = ctx_.originX + lx, gy = ctx_.originY + ly;
    int hidden = 0;
    const float uniform[2] = {ctx_.clearPlanes ? ctx_.clearPlanes[0] : 0.0f, sampleDepthMax_};
    const bool any = samplesPassing(t_, planeLanes_, *ctx_.coverage, sampleDepth_, masks, gx, gy,
                                    blockDepthOrClear(planes), b.pass, cx, cy, shading, hidden,
                                    ctx_.sums ? uniform : nullptr);
    ctx_.stats->hiddenFragments += uint64_t(hidden);
    if (!any) return;
    int passing = 0;
    for (int l = 0; l < kBlockPixels; ++l) passing += (b.pass[0][l] | b.pass[1][l]) != 0;
    if (passing == kBlockPixels) {
      // A block whose every pixel passes fills the lanes by itself: shaded and written at once.
      const shade::MaterialShading& m = *attributes_->material;
      alignas(32) float base[8];
      blockBases(t_, planeLanes_, gx, gy, base);
      shade::Fragments f;
      blockFragments(t_, planeLanes_, attributeLanes_, base, gx, gy, cx, cy,
                     shade::attributesUsed(m, *ctx_.environment), f);
      alignas(64) float rgba[4][kBlockPixels];
      shade::shadeFragments(m, *ctx_.environment, f, rgba);
      writeSamples(t_, planeLanes_, m, sampleDepth_, ctx_.samples, b.pass, rgba, gx, gy,
                   ctx_.depth + planes * kBlockPixels, ctx_.color + planes * kColorPerBlock,
                   blockSums(block), ctx_.clearColor);
      return;
    }
    b.lx = lx;
    b.ly = ly;
    b.markAfter = false;
    b.firstPixel = pendingPixels_;
    const float bx = float(gx - t_.minX), by = float(gy - t_.minY);
    for (int l = 0; l < kBlockPixels; ++l) {
      if (!(b.pass[0][l] | b.pass[1][l])) continue;
      const int p = pendingPixels_++;
      pixelX_[p] = bx;
      pixelY_[p] = by;
      pixelLane_[p] = l;
      pixelCx_[p] = cx[l];
      pixelCy_[p] = cy[l];
    }
    b.pixelCount = pendingPixels_ - b.firstPixel;
    if (++pendingBlocks_ == kPendingBlocks) flushSamples();
  }

  // Steps 2 and 3 for the queued blocks: their pixels shaded 16 at a time, then written.
  void flushSamples() {
    if (pendingBlocks_ == 0) return;
    const shade::MaterialShading& m = *attributes_->material;
    const unsigned used = shade::attributesUsed(m, *ctx_.environment);
    // All batches' texture coordinates first, which requests their texels (shadeVisible's queue).
    constexpr int kBatches = kPendingPixels / kBlockPixels;
    shade::Fragments f[kBatches];
    shade::TexCoords coordinates[kBatches];
    for (int first = 0; first < pendingPixels_; first += kBlockPixels) {
      const int count = std::min(kBlockPixels, pendingPixels_ - first);
      // Unused lanes repeat the last pixel: valid positions, no extra texels.
      for (int l = count; l < kBlockPixels; ++l) {
        const int last = first + count - 1, p = first + l;
        pixelX_[p] = pixelX_[last];
        pixelY_[p] = pixelY_[last];
        pixelLane_[p] = pixelLane_[last];
        pixelCx_[p] = pixelCx_[last];
        pixelCy_[p] = pixelCy_[last];
      }
      const int batch = first / kBlockPixels;
      batchFragments(planeLanes_, attributeLanes_, pixelX_ + first, pixelY_ + first,
                     pixelLane_ + first, pixelCx_ + first, pixelCy_ + first, used, f[batch]);
      if (m.texture) shade::textureCoordinates(m, f[batch], coordinates[batch]);
    }
    for (int first = 0; first < pendingPixels_; first += kBlockPixels) {
      const int count = std::min(kBlockPixels, pendingPixels_ - first),
                batch = first / kBlockPixels;
      alignas(64) float rgba[4][kBlockPixels];
      if (m.texture)
        shade::shadeFragments(m, *ctx_.environment, f[batch], coordinates[batch], rgba);
      else
        shade::shadeFragments(m, *ctx_.environment, f[batch], rgba);
      for (int ch = 0; ch < 4; ++ch) std::copy_n(rgba[ch], count, pixelRgba_[ch] + first);
    }
    for (int i = 0; i < pendingBlocks_; ++i) {
      const PendingBlock& b = pending_[i];
      alignas(64) float rgba[4][kBlockPixels] = {};
      for (int k = 0; k < b.pixelCount; ++k) {
        const int p = b.firstPixel + k;
        for (int ch = 0; ch < 4; ++ch) rgba[ch][pixelLane_[p]] = pixelRgba_[ch][p];
      }
      const size_t block = tileBlock(b.lx, b.ly);
      const size_t planes = block * size_t(ctx_.samples);
      writeSamples(t_, planeLanes_, m, sampleDepth_, ctx_.samples, b.pass, rgba,
                   ctx_.originX + b.lx, ctx_.originY + b.ly, ctx_.depth + planes * kBlockPixels,
                   ctx_.color + planes * kColorPerBlock, blockSums(block), ctx_.clearColor);
      if (b.markAfter) markSamples(b.lx, b.ly, b.marks);
    }
    pendingBlocks_ = pendingPixels_ = 0;
  }

  struct PendingBlock {
    int lx, ly, firstPixel, pixelCount;
    bool markAfter;  // hybrid: occupy `marks` once written (markOrDefer)
    alignas(64) uint32_t pass[2][kBlockPixels];
    alignas(64) uint32_t marks[2][kBlockPixels];
  };
  static constexpr int kPendingBlocks = 16;
  static constexpr int kPendingPixels = kPendingBlocks * kBlockPixels;
  // Only the AA material path uses these (left uninitialized otherwise: written before read).
  PendingBlock pending_[kAA && kOp == PixelOp::material ? kPendingBlocks : 1];
  int pendingBlocks_ = 0, pendingPixels_ = 0;
  static constexpr int kPixelSlots =
      kAA && kOp == PixelOp::material ? kPendingPixels + kBlockPixels : 1;
  alignas(64) float pixelX_[kPixelSlots], pixelY_[kPixelSlots];
  alignas(64) int32_t pixelLane_[kPixelSlots];
  alignas(64) float pixelCx_[kPixelSlots], pixelCy_[kPixelSlots];
  alignas(64) float pixelRgba_[4][kPixelSlots];

  const TriangleSetup& t_;
  const TileContext& ctx_;
  const AttributeSetup* attributes_;                   // PixelOp::material
  const uint32_t id_;                                  // PixelOp::visibility
  Occupancy* occ_ = nullptr;                           // masking: drop occupied windows
  bool mark_ = false;                                  // … and occupy what this triangle covers
  int boxX0_ = 0, boxY0_ = 0, boxX1_ = 0, boxY1_ = 0;  // the box inside the tile (draw)
  int drawLevel_ = 1;                                  // PixelOp::levels: what shade() records
  float boxZmin_ = 0;  // hybrid: the triangle's smallest depth in that box
  T sX_[E], sY_[E], pos_[E], neg_[E];
  alignas(64) T leafOffset_[E][kBlockPixels];
  PlaneLanes planeLanes_;
  AttributeLanes attributeLanes_;  // PixelOp::material
  // Anti-aliasing only (setUpSamples).
  T rejectOffset_[E], acceptOffset_[E], bias_[E];
  int32_t rowOffset_[E], divisor_[E];
  float reciprocal_[E];
  float sampleDepth_[64];
  float sampleDepthMax_ = 0;  // the largest of them
};

void clearTile(const TileWork& w) {
  const int samples = w.coverage ? w.coverage->samples : 1;
  if (w.sums) {  // N samples of the clear colour; the planes are not used
    for (int b = 0; b < kTilePixels / kBlockPixels; ++b)
      for (int ch = 0; ch < kColorChannels; ++ch)
        std::fill_n(w.sums + size_t(b) * kColorPerBlock + ch * kBlockPixels, kBlockPixels,
                    int32_t(w.clearColor[ch]) * samples);
    return;
  }
  const int planes = kTilePixels / kBlockPixels * samples;
  std::fill(w.depth, w.depth + size_t(planes) * kBlockPixels, w.clearDepth);
  // One plane's worth, copied whole (two or three vector stores): 3 fills of 16 values per plane
  // were 5 % of a 4-sample frame.
  alignas(64) uint16_t plane[kColorPerBlock];
  for (int ch = 0; ch < kColorChannels; ++ch)
    std::fill_n(plane + ch * kBlockPixels, kBlockPixels, w.clearColor[ch]);
  for (int b = 0; b < planes; ++b)
    std::memcpy(w.color + size_t(b) * kColorPerBlock, plane, sizeof(plane));
}

// Priority masking: whether the triangle with box (minX, minY)–(maxX, maxY) lies in occupied
// windows of the tile, so that it is dropped before its traversal is set up (in a deep stack of
// layers, most are); counted as occluded. Hybrid masking (`t`): in full windows whose depth bounds
// its nearest depth does not beat. Also true, uncounted, for a box outside the tile.
template <bool kAA>
HWY_INLINE bool boxHidden(const TileContext& ctx, int minX, int minY, int maxX, int maxY,
                          const TriangleSetup* t = nullptr) {
  const int x0 = std::max(minX - ctx.originX, 0), y0 = std::max(minY - ctx.originY, 0);
  const int x1 = std::min(maxX - ctx.originX, kTileSize - 1);
  const int y1 = std::min(maxY - ctx.originY, kTileSize - 1);
  if (x0 > x1 || y0 > y1) return true;  // (the traversal would draw nothing)
  const bool hidden = ctx.hybrid ? ctx.occupancy->rectHidden(
                                       x0, y0, x1, y1,
                                       depthBound(*t, ctx.originX + x0, ctx.originY + y0,
                                                  ctx.originX + x1, ctx.originY + y1, kAA, false))
                                 : ctx.occupancy->rectFull(x0, y0, x1, y1);
  ctx.stats->occludedTriangles += hidden;
  return hidden;
}

// One triangle, specialized on its edge count and integer width (STYLE.md habit 6).
// `boxTested`: boxHidden has passed it already (TileWork::listBoxes).
template <PixelOp kOp, bool kAA>
HWY_INLINE void drawTriangle(const TriangleSetup& t, const TileContext& ctx,
                             const AttributeSetup* attributes = nullptr, uint32_t id = kNoTriangle,
                             bool boxTested = false) {
  if (ctx.occupancy && !boxTested &&
      !(attributes && attributes->material &&
        attributes->material->alpha == shade::AlphaUse::blend) &&
      boxHidden<kAA>(ctx, t.minX, t.minY, t.maxX, t.maxY, &t))
    return;
  if (t.small) return TriangleRaster<3, kOp, int32_t, kAA>(t, ctx, attributes, id).draw();
  switch (t.edgeCount) {
    case 3:
      return TriangleRaster<3, kOp, int64_t, kAA>(t, ctx, attributes, id).draw();
    case 4:
      return TriangleRaster<4, kOp, int64_t, kAA>(t, ctx, attributes, id).draw();
    default:
      return TriangleRaster<5, kOp, int64_t, kAA>(t, ctx, attributes, id).draw();
  }
}

// Masking woken in a tile (drawLists): the occupancy rebuilt from the depth buffer as it stands.
// A sample holding a surface (depth below the clear value) is occupied — drawn by the nearest
// primitive so far, which with priority masking is final; a block all of whose samples are is full,
// with hybrid masking bounded by their largest depth. That is what marking from the tile's first
// triangle would have left (with depth, the same bounds markSamples reads), or more.
HWY_NOINLINE void occupyFromDepth(const TileContext& ctx, float clearDepth) {
  Occupancy& occ = *ctx.occupancy;
  occ.clear(ctx.samples);
  const hn::CappedTag<float, kBlockPixels> df;
  const hn::RebindToUnsigned<decltype(df)> du;
  const size_t lanes = hn::Lanes(df);
  const int samples = ctx.samples;
  const auto clear = hn::Set(df, clearDepth);
  const auto full0 = hn::Set(du, occ.fullWords()[0]), full1 = hn::Set(du, occ.fullWords()[1]);
  const float* depth = ctx.depth;
  for (int ly = 0; ly < kTileSize; ly += kBlockSize)
    for (int lx = 0; lx < kTileSize; lx += kBlockSize, depth += size_t(samples) * kBlockPixels) {
      alignas(64) uint32_t words[2][kBlockPixels];
      auto zmax = hn::Set(df, -Occupancy::kNoBound);
      uint32_t pixels = 0, any = 0;
      for (size_t i = 0; i < size_t(kBlockPixels); i += lanes) {
        auto w0 = hn::Zero(du), w1 = w0;
        for (int s = 0; s < samples; ++s) {
          const auto z = hn::LoadU(df, depth + size_t(s) * kBlockPixels + i);
          zmax = hn::Max(zmax, z);
          orSampleBit(du, hn::RebindMask(du, hn::Lt(z, clear)), s, w0, w1);
        }
        hn::StoreU(w0, du, words[0] + i);
        hn::StoreU(w1, du, words[1] + i);
        pixels |= laneBits(du, hn::And(hn::Eq(w0, full0), hn::Eq(w1, full1)), i);
        any |= laneBits(du, hn::Ne(hn::Or(w0, w1), hn::Zero(du)), i);
      }
      if (pixels == 0xFFFF) {
        occ.markFull(kBlockLog2, lx, ly,
                     ctx.hybrid ? hn::GetLane(hn::MaxOfLanes(df, zmax)) : Occupancy::kNoBound);
      } else if (any) {
        std::memcpy(occ.sampleWords(lx, ly), words, sizeof(words));
        occ.setPixels(lx, ly, pixels);
      }
    }
}

// The tile's opaque surfaces are all in: TileWork::afterOpaque's passes, once.
void afterOpaque(const TileWork& w) {
  if (w.afterOpaque.empty() || !w.opaqueDone || *w.opaqueDone) return;
  *w.opaqueDone = true;
  const TileTarget target{w.tileX, w.tileY, w.depth, w.color, w.worker};
  for (TilePass* pass : w.afterOpaque) pass->drawTile(target);
}

template <ShadeMode kShade, bool kAA>
void drawLists(const TileWork& w, RasterStats& stats) {
  // Pixel shading at one sample is deferred: opaque triangles only record the winner per pixel.
  const bool deferred = kShade == ShadeMode::material && !kAA;
  TileContext ctx{
      w.tileX * kTileSize,
      w.tileY * kTileSize,
      w.depth,
      w.color,
      &stats,
      w.coverage,
      w.coverage ? w.coverage->samples : 1,
      w.environment,
      deferred ? w.visible : nullptr,
      w.setups,
      w.attributes,
      kShade == ShadeMode::overdraw || w.masking == Masking::none ? nullptr : w.occupancy,
      w.masking == Masking::hybrid};
  WinnerList winners;
  if (deferred) ctx.winners = &winners;
  alignas(64) float clearPlanes[64 * kBlockPixels];
  if (w.sums) {
    std::fill_n(clearPlanes, ctx.samples * kBlockPixels, w.clearDepth);
    ctx.sums = w.sums;
    ctx.clearPlanes = clearPlanes;
    for (int ch = 0; ch < kColorChannels; ++ch) ctx.clearColor[ch] = w.clearColor[ch];
  }
  // Hybrid masking pays only where triangles arrive behind what is drawn; elsewhere (one layer, or
  // back-to-front input) its marking and checks are pure cost. So a tile starts as the plain
  // Z-buffer (`plain`, no occupancy) and wakes when the depth test has hidden kWakeWork: pixels
  // that passed none of their samples, a triangle hidden whole counting at least
  // kHiddenTriangleWork (its traversal costs that much however few pixels it has, and culling it
  // whole is what masking does best): the occupancy is rebuilt from the depth buffer and masking
  // runs from there on — if at least a quarter of the tile's triangles are still to come: the
  // rebuild reads the whole depth buffer, which a few remaining triangles do not repay (random
  // order at D = 2 reaches kWakeWork near the end of a tile's list: waking there made the frame
  // 2 % slower than the Z-buffer's). The
  // image is the Z-buffer's either way; only the work differs (docs/hidden-surfaces.md). The
  // first batch's pass over a tile starts so; one that ends asleep wakes before the next batch,
  // whose object culling before setup reads the occupancy. (Not priority masking: its order may
  // overrule depth — stated priorities — which the Z-buffer would not honour.)
  TileContext plain = ctx;
  plain.occupancy = nullptr;
  constexpr uint64_t kWakeWork = kTilePixels / 2, kHiddenTriangleWork = 64;
  const TileContext* use =
      ctx.occupancy && ctx.hybrid && w.clear && !w.debugOccupancy ? &plain : &ctx;
  uint64_t hiddenWork = 0;
  uint64_t entries = 0, entriesDone = 0;  // the tile's list entries, and those drawn so far
  for (int l = 0; l < w.listCount; ++l) entries += w.listSizes[l];
  auto wake = [&] {
    occupyFromDepth(ctx, w.clearDepth);
    use = &ctx;
    ++stats.hybridWoken;
  };
  // After a triangle drawn asleep, with the fragment counts as they were before it.
  auto wakeIfHidden = [&](uint64_t fragments, uint64_t hidden) {
    if (use != &plain) return;
    const uint64_t drawn = stats.fragments - fragments;
    hidden = stats.hiddenFragments - hidden;
    hiddenWork += drawn > 0 && hidden == drawn ? std::max(hidden, kHiddenTriangleWork) : hidden;
    if (hiddenWork >= kWakeWork && 4 * (entries - entriesDone) >= entries) wake();
  };
  bool pending = false;  // some pixel records a triangle not yet shaded
  // Setup records are read in bin order, scattered over the batch: fetch a few ahead, the loop is
  // otherwise bound by their cache misses. (Before records were grouped by tile this was half the
  // tile time on 10-px triangles; now 2 ahead measures the same as 1 and better than 4 or 8.)
  constexpr uint32_t kPrefetchDistance = 2;
  static_assert(offsetof(AttributeSetup, planes) == sizeof(void*) && alignof(AttributeSetup) == 64);
  const shade::MaterialShading* lastMaterial = nullptr;
  bool wideRecords = true;
  // Object-space culling: the object last tested, and whether it was hidden. A hidden object stays
  // hidden (occupancy only grows and depth bounds only fall), so the answer holds across lists.
  uint32_t lastObject = kNoObject;
  bool objectIsHidden = false;
  for (int l = 0; l < w.listCount; ++l) {
    const uint32_t* list = w.lists[l];
    const uint32_t size = w.listSizes[l];
    const uint32_t* objects = ctx.occupancy && w.listObjects ? w.listObjects[l] : nullptr;
    const Binner::Box* boxes =
        ctx.occupancy && !ctx.hybrid && w.listBoxes ? w.listBoxes[l] : nullptr;
    for (uint32_t i = 0; i < size; ++i, ++entriesDone) {
      if (objects && use->occupancy && objects[i] != kNoObject) {
        const uint32_t object = objects[i];
        if (object != lastObject) {
          lastObject = object;
          objectIsHidden =
              objectHidden(*ctx.occupancy, w.objects[object], w.tileX, w.tileY, w.masking);
          stats.occludedObjects += objectIsHidden;
        }
        if (objectIsHidden) {  // the rest of its run, unread
          uint32_t end = i + 1;
          while (end < size && objects[end] == object) ++end;
          stats.occludedTriangles += end - i;
          entriesDone += end - 1 - i;
          i = end - 1;
          continue;
        }
      }
      if (boxes && boxHidden<kAA>(ctx, boxes[i].minX, boxes[i].minY, boxes[i].maxX, boxes[i].maxY))
        continue;
      if (i + kPrefetchDistance < size) {
        const uint32_t ahead = list[i + kPrefetchDistance];
        const char* next = reinterpret_cast<const char*>(w.setups + ahead);
        for (size_t line = 0; line < sizeof(TriangleSetup); line += 64) hwy::Prefetch(next + line);
        // Pixel shading's record sits at the same index (TileWork::attributes).
        if (kShade == ShadeMode::material) {
          // The record's first line holds the material and the texture planes; the second the
          // rest, requested while the materials seen last read any of it.
          const char* record = reinterpret_cast<const char*>(w.attributes + ahead);
          hwy::Prefetch(record);
          if (wideRecords) hwy::Prefetch(record + 64);
        }
      }
      const TriangleSetup& t = w.setups[list[i]];
      const uint64_t fragmentsBefore = stats.fragments, hiddenBefore = stats.hiddenFragments;
      if constexpr (kShade == ShadeMode::material) {
        // Per triangle: shaded per pixel when it has a material, else plain Gouraud.
        const AttributeSetup& a = w.attributes[list[i]];
        if (a.material != lastMaterial) {
          lastMaterial = a.material;
          // Triangles shaded as they are drawn (anti-aliased, or not opaque) read every plane
          // (computeAttributeLanes); deferred ones only those their material uses.
          wideRecords =
              a.material &&
              (!deferred || a.material->alpha != shade::AlphaUse::opaque ||
               AttributeSetup::readsSecondLine(shade::attributesUsed(*a.material, *w.environment)));
        }
        const shade::AlphaUse alpha = a.material ? a.material->alpha : shade::AlphaUse::opaque;
        if (deferred && alpha == shade::AlphaUse::opaque) {
          drawTriangle<PixelOp::visibility, false>(t, *use, nullptr, list[i], boxes != nullptr);
          if (stats.fragments - fragmentsBefore > stats.hiddenFragments - hiddenBefore)
            winners.add(list[i], std::max(t.minX - ctx.originX, 0),
                        std::max(t.minY - ctx.originY, 0),
                        std::min(t.maxX - ctx.originX, kTileSize - 1),
                        std::min(t.maxY - ctx.originY, kTileSize - 1));
          pending = true;
          wakeIfHidden(fragmentsBefore, hiddenBefore);
          continue;
        }
        // Blending reads the colour behind: the deferred pixels must have theirs first, and the
        // opaque free forms must be in.
        if (alpha == shade::AlphaUse::blend) {
          if (pending) shadeVisible(ctx);
          pending = false;
          afterOpaque(w);
        }
        if (a.material)
          drawTriangle<PixelOp::material, kAA>(t, *use, &a, kNoTriangle, boxes != nullptr);
        else
          drawTriangle<PixelOp::gouraud, kAA>(t, *use, nullptr, kNoTriangle, boxes != nullptr);
      } else {
        constexpr PixelOp op = kShade == ShadeMode::overdraw ? PixelOp::overdraw
                               : kShade == ShadeMode::levels ? PixelOp::levels
                                                             : PixelOp::gouraud;
        drawTriangle<op, kAA>(t, *use, nullptr, kNoTriangle, boxes != nullptr);
      }
      wakeIfHidden(fragmentsBefore, hiddenBefore);
    }
  }
  if (pending) shadeVisible(ctx);
  if (use == &plain && !w.lastBatch) wake();
  if (w.lastBatch) afterOpaque(w);
}

void RasterizeTile(const TileWork& w, RasterStats& stats) {
  if (w.clear) clearTile(w);
  if (w.clear && w.occupancy) w.occupancy->clear(w.coverage ? w.coverage->samples : 1);
  if (w.shade == ShadeMode::overdraw)
    drawLists<ShadeMode::overdraw, false>(w, stats);
  else if (w.shade == ShadeMode::levels)
    drawLists<ShadeMode::levels, false>(w, stats);
  else if (w.shade == ShadeMode::material && w.coverage)
    drawLists<ShadeMode::material, true>(w, stats);
  else if (w.shade == ShadeMode::material)
    drawLists<ShadeMode::material, false>(w, stats);
  else if (w.coverage)
    drawLists<ShadeMode::gouraud, true>(w, stats);
  else
    drawLists<ShadeMode::gouraud, false>(w, stats);
  if (w.debugOccupancy && w.occupancy) occupancyView(*w.occupancy, w.color);
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::raster
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sv::raster {
HWY_EXPORT(RasterizeTile);

void rasterizeTile(const TileWork& work, RasterStats& stats) {
  // The kernel counts into its own stack's copy: callers keep neighbouring tiles' statistics next
  // to each other, and two threads counting windows into one cache line slowed whole frames
  // (false sharing; docs/performance.md).
  RasterStats local;
  HWY_DYNAMIC_DISPATCH(RasterizeTile)(work, local);
  stats.add(local);
}
}  // namespace sv::raster
#endif
