// The tile kernel's shared vocabulary (Highway, per target): lane constants, what a covered pixel
// does (PixelOp), the tile's context, the base parameter planes per 4×4 block (PlaneLanes), colour
// to 16-bit lanes, hybrid masking's depth bounds.
//
// Based on: SPEC §2 (parameters linear in screen space, perspective correction by 1/w), §4.
//
// Per-target include guard (Highway's convention for -inl.h files): included by tile_kernel.cpp,
// once per SIMD target, so that everything here inlines into the kernel.
#if defined(SV_RASTER_KERNEL_COMMON_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef SV_RASTER_KERNEL_COMMON_INL_H_
#undef SV_RASTER_KERNEL_COMMON_INL_H_
#else
#define SV_RASTER_KERNEL_COMMON_INL_H_
#endif

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "core/masked_store-inl.h"
#include "hwy/highway.h"
#include "raster/framebuffer.h"
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
// Lane i holds i (a block's pixel numbers, from its first).
alignas(64) constexpr int32_t kLaneIndex[kBlockPixels] = {0, 1, 2,  3,  4,  5,  6,  7,
                                                          8, 9, 10, 11, 12, 13, 14, 15};

// What TriangleRaster does with a covered pixel (ShadeMode, refined): count it; depth-test and
// write Gouraud colour; depth-test and shade it now (shade::shadeFragments); or depth-test and
// record which triangle won (visibility), to be shaded once per pixel when the tile's triangles are
// all drawn (shadeVisible).
enum class PixelOp : uint8_t { overdraw, gouraud, material, visibility, levels };

// Visibility: "no triangle recorded since the last shading pass".
constexpr uint32_t kNoTriangle = ~0u;

// Deferred shading's list of the triangles that won pixels (deferred_shading-inl.h).
struct WinnerList;

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
// once per triangle. Every target, and the scalar form geometry::planeAtPixel (the reference in
// tests/support, the segment pipeline), computes exactly these float operations in this order,
// which is what makes them bit-identical.
enum PlaneIndex { kDepth, kInvW, kRed, kGreen, kBlue, kPlaneCount };

struct PlaneLanes {
  alignas(64) float offset[kPlaneCount][kBlockPixels];
  // The planes' c0, dx, dy side by side, so a block's five bases are one vector expression.
  alignas(32) float c0[8], dx[8], dy[8];
};

using core::HWY_NAMESPACE::storeWhere;  // the masked store of every block operation

// The pass mask of float lanes as a mask of as many 16-bit lanes, for masked colour stores: a third
// of the instructions of widening, blending and narrowing each channel. The mask as a vector of
// 32-bit lanes, narrowed (−1 stays −1 under the saturating demotion).
template <class DF, class M>
HWY_INLINE auto passMask16(DF, M pass) {
  const hn::RebindToSigned<DF> di;
  const hn::Rebind<int16_t, DF> d16;
  const hn::Rebind<uint16_t, DF> du;
  return hn::MaskFromVec(
      hn::BitCast(du, hn::DemoteTo(d16, hn::VecFromMask(di, hn::RebindMask(di, pass)))));
}

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

// The same for a run of `count` blocks in a row from the block at (gx, gy): plane p at block j's
// top-left pixel in base[p][j], for the first `planes` planes. Lane by lane these are blockBases'
// float operations, so the values are the same bit for bit; a run of full blocks takes one vector
// expression per plane instead of one per block.
HWY_INLINE void runBases(const TriangleSetup& t, const PlaneLanes& lanes, int gx, int gy,
                         int count, int planes, float (*base)[kBlocksPerTileSide]) {
  const hn::CappedTag<float, kBlocksPerTileSide> df;
  const hn::RebindToSigned<decltype(df)> di;
  const auto by = hn::Set(df, float(gy - t.minY));
  for (size_t i = 0; i < size_t(count); i += hn::Lanes(df)) {
    // Block j's x, relative to the planes' origin: gx − minX + 4·j, exact in float.
    const auto bx = hn::ConvertTo(df, hn::Add(hn::Set(di, gx - t.minX),
                                              hn::ShiftLeft<kBlockLog2>(
                                                  hn::LoadU(di, kLaneIndex + i))));
    for (int p = 0; p < planes; ++p)
      hn::Store(hn::Add(hn::Add(hn::Set(df, lanes.c0[p]), hn::Mul(hn::Set(df, lanes.dx[p]), bx)),
                        hn::Mul(hn::Set(df, lanes.dy[p]), by)),
                df, base[p] + i);
  }
}

// 0…1 → 16-bit linear light in int32 lanes. Float → 16-bit by the magic-number trick: for
// 0 ≤ v < 2^23, the float v + 2^23 holds round-to-nearest-even(v) in its low mantissa bits (no
// range fix-ups, unlike ConvertTo).
template <class DF, class V>
HWY_INLINE auto unitToLanes(DF df, V c) {
  const hn::RebindToSigned<DF> di;
  return hn::And(
      hn::BitCast(di, hn::Add(hn::Mul(c, hn::Set(df, 65535.0f)), hn::Set(df, 8388608.0f))),
      hn::Set(di, 0xFFFF));
}

// Perspective-correct colour (colour/w)·w, clamped to [0, 1], as unitToLanes' 16-bit lanes.
template <class DF, class V>
HWY_INLINE auto colorToLanes(DF df, V cw, V w) {
  return unitToLanes(df, hn::Min(hn::Max(hn::Mul(cw, w), hn::Zero(df)), hn::Set(df, 1.0f)));
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

}  // namespace HWY_NAMESPACE
}  // namespace sv::raster
HWY_AFTER_NAMESPACE();

#endif  // SV_RASTER_KERNEL_COMMON_INL_H_
