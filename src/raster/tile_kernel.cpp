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
// — the largest value of e over the window's pixel centres. With sX⁺ = max(sX, 0), sX⁻ = min(sX, 0):
//     d      = tl + (sX⁺ + sY⁺)·(n − 1)        d < 0   → the window is outside: reject
//     d − 2ε = tl + (sX⁻ + sY⁻)·(n − 1)        d ≥ 2ε  → inside this edge: drop the edge below here
// A child of size h = n/2 at (cx, cy) ∈ {0,1}² has tl' = tl + cx·sX·h + cy·sY·h (seed 000 eq. 1), so
// its d' = d − h·|sX|·e_A − h·|sY|·e_B + … is seed 000's eq. 8 with the ε of the child folded in; we
// carry tl rather than d because it is the same for every level's ε (one add per edge per child,
// as the seed counts). All in exact int64 (budget in geometry/setup.h).
//
// Departure from the seed: the last two levels (2×2 and 1×1 windows) are unrolled into one 4×4 leaf
// whose 16 pixel centres are tested at once in SIMD lanes; the result is the same set of pixels.

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/tile_kernel.cpp"
#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"

#include <algorithm>
#include <bit>

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
constexpr int32_t kLaneX[kBlockPixels] = {0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3};
constexpr int32_t kLaneY[kBlockPixels] = {0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3};

struct TileContext {
  int originX, originY;  // pixel coordinates of the tile's top-left pixel
  float* depth;
  uint16_t* color;
  RasterStats* stats;
};

// Evaluates a plane at lanes' pixel positions: c0 + dx·X + dy·Y, in this order (the scalar twin in
// tests/raster does the same, which is what makes every target bit-identical).
template <class DF, class VF>
HWY_INLINE VF evalPlane(DF df, const Plane& p, VF x, VF y) {
  return hn::Add(hn::Add(hn::Set(df, p.c0), hn::Mul(hn::Set(df, p.dx), x)),
                 hn::Mul(hn::Set(df, p.dy), y));
}

// Overdraw count: +1 in the red channel of every pixel set in `mask` (no depth test).
HWY_INLINE void countBlock(uint32_t mask, uint16_t* color) {
  for (; mask; mask &= mask - 1) ++color[std::countr_zero(mask)];
}

// Depth test ("less") and Gouraud colour for the pixels of one 4×4 block set in `mask`.
// (gx, gy) is the block's top-left pixel; `depth` and `color` point at the block's storage.
HWY_INLINE void shadeBlock(const TriangleSetup& t, uint32_t mask, int gx, int gy, float* depth,
                           uint16_t* color) {
  const hn::CappedTag<float, kBlockPixels> df;
  const hn::RebindToSigned<decltype(df)> di;
  const hn::Rebind<uint16_t, decltype(df)> du;
  const size_t n = hn::Lanes(df);
  const auto maskVec = hn::Set(di, static_cast<int32_t>(mask));
  const auto dx0 = hn::Set(di, gx - t.refX), dy0 = hn::Set(di, gy - t.refY);
  const auto zero = hn::Zero(df), one = hn::Set(df, 1.0f);
  const auto scale = hn::Set(df, 65535.0f), half = hn::Set(df, 0.5f);
  for (size_t i = 0; i < size_t(kBlockPixels); i += n) {
    const auto covered = hn::TestBit(maskVec, hn::LoadU(di, kLaneBit + i));
    if (hn::AllFalse(di, covered)) continue;
    const auto x = hn::ConvertTo(df, hn::Add(dx0, hn::LoadU(di, kLaneX + i)));
    const auto y = hn::ConvertTo(df, hn::Add(dy0, hn::LoadU(di, kLaneY + i)));
    // SPEC §4: Z-buffer — depth is a §2 parameter, linear in screen space.
    const auto z = evalPlane(df, t.depth, x, y);
    const auto zOld = hn::LoadU(df, depth + i);
    const auto pass = hn::And(hn::RebindMask(df, covered), hn::Lt(z, zOld));
    if (hn::AllFalse(df, pass)) continue;
    hn::StoreU(hn::IfThenElse(pass, z, zOld), df, depth + i);
    // SPEC §2: perspective-correct colour = (colour/w) / (1/w).
    const auto w = hn::Div(one, evalPlane(df, t.invW, x, y));
    const auto passI = hn::RebindMask(di, pass);
    const Plane* planes[kColorChannels] = {&t.red, &t.green, &t.blue};
    for (int ch = 0; ch < kColorChannels; ++ch) {
      const auto c = hn::Min(hn::Max(hn::Mul(evalPlane(df, *planes[ch], x, y), w), zero), one);
      const auto c16 = hn::ConvertTo(di, hn::Add(hn::Mul(c, scale), half));
      uint16_t* dst = color + ch * kBlockPixels + i;
      const auto old = hn::PromoteTo(di, hn::LoadU(du, dst));
      hn::StoreU(hn::DemoteTo(du, hn::IfThenElse(passI, c16, old)), du, dst);
    }
  }
}

template <int E, ShadeMode kShade>
class TriangleRaster {
 public:
  TriangleRaster(const TriangleSetup& t, const TileContext& ctx) : t_(t), ctx_(ctx) {
    for (int k = 0; k < E; ++k) {
      const auto& e = t.edges[k];
      sX_[k] = e.stepX;
      sY_[k] = e.stepY;
      pos_[k] = std::max<int64_t>(e.stepX, 0) + std::max<int64_t>(e.stepY, 0);
      neg_[k] = std::min<int64_t>(e.stepX, 0) + std::min<int64_t>(e.stepY, 0);
      for (int x = 0; x < kBlockSize; ++x) rowOffset_[k][x] = e.stepX * x;
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
    // Step 2: start the descent at the aligned cell size that matches the triangle's extent
    // (SPEC §3 allows any initial window): the box then spans at most 2×2 cells, and a triangle of
    // a few pixels starts directly at a 4×4 leaf instead of descending from the whole screen.
    const int extent = std::max(x1 - x0, y1 - y0) + 1;
    const int log2n = std::max(kBlockLog2, int(std::bit_width(unsigned(extent - 1))));
    const int n = 1 << log2n;
    for (int cy = y0 >> log2n; cy <= y1 >> log2n; ++cy)
      for (int cx = x0 >> log2n; cx <= x1 >> log2n; ++cx) visitRoot(cx << log2n, cy << log2n, log2n, n);
  }

 private:
  int64_t edgeAt(int k, int lx, int ly) const {
    return t_.edges[k].c + sX_[k] * (ctx_.originX + lx) + sY_[k] * (ctx_.originY + ly);
  }

  static int statLevel(int log2n) { return kTileLog2 - log2n; }

  // Classifies a root window by the coverage function of each edge, then fills, tests or splits.
  void visitRoot(int lx, int ly, int log2n, int n) {
    ++ctx_.stats->windows[statLevel(log2n)];
    int64_t tl[kMaxEdges];
    unsigned active = 0;
    for (int k = 0; k < E; ++k) {
      tl[k] = edgeAt(k, lx, ly);
      if (tl[k] + pos_[k] * (n - 1) < 0) return;             // d < 0: outside
      if (tl[k] + neg_[k] * (n - 1) < 0) active |= 1u << k;  // d < 2ε: the edge crosses
    }
    descend(lx, ly, log2n, tl, active);
  }

  void descend(int lx, int ly, int log2n, const int64_t* tl, unsigned active) {
    if (active == 0) return fill(lx, ly, 1 << log2n);
    if (log2n == kBlockLog2) return leaf(lx, ly, tl, active);
    split(lx, ly, log2n, tl, active);
  }

  // SPEC §3.5: the four children of a window are tested together, one SIMD lane per child.
  void split(int lx, int ly, int log2n, const int64_t* tl, unsigned active) {
    const int hLog2 = log2n - 1;
    const int64_t h = int64_t(1) << hLog2;
    const hn::CappedTag<int64_t, 4> d;
    const size_t lanes = hn::Lanes(d);
    const auto zero = hn::Zero(d), minusOne = hn::Set(d, -1);  // x ≥ 0 ⇔ x > −1 on integers
    alignas(32) int64_t childTl[kMaxEdges][4];
    unsigned rejected = 0;
    unsigned accepted[kMaxEdges] = {};
    for (int k = 0; k < E; ++k) {
      if (!(active & (1u << k))) continue;
      const int64_t offsets[4] = {0, sX_[k] * h, sY_[k] * h, (sX_[k] + sY_[k]) * h};
      const auto base = hn::Set(d, tl[k]);
      const auto dMax = hn::Set(d, pos_[k] * (h - 1));
      const auto dMin = hn::Set(d, neg_[k] * (h - 1));
      for (size_t i = 0; i < 4; i += lanes) {
        const auto ctl = hn::Add(base, hn::LoadU(d, offsets + i));
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
      unsigned childActive = active;
      int64_t ctl[kMaxEdges] = {};
      for (int k = 0; k < E; ++k) {
        if (!(active & (1u << k))) continue;
        if (accepted[k] & (1u << c)) childActive &= ~(1u << k);
        ctl[k] = childTl[k][c];
      }
      descend(lx + (c & 1) * int(h), ly + (c >> 1) * int(h), hLog2, ctl, childActive);
    }
  }

  // A 4×4 leaf crossed by the `active` edges: test all 16 pixel centres in SIMD lanes.
  void leaf(int lx, int ly, const int64_t* tl, unsigned active) {
    const hn::CappedTag<int64_t, 4> d;
    const size_t lanes = hn::Lanes(d);
    const auto minusOne = hn::Set(d, -1);
    uint32_t mask = 0xFFFF;
    for (int k = 0; k < E && mask; ++k) {
      if (!(active & (1u << k))) continue;
      uint32_t edgeMask = 0;
      for (int row = 0; row < kBlockSize; ++row) {
        const auto base = hn::Set(d, tl[k] + sY_[k] * row);
        for (size_t i = 0; i < size_t(kBlockSize); i += lanes) {
          uint8_t bits = 0;
          hn::StoreMaskBits(d, hn::Gt(hn::Add(base, hn::LoadU(d, rowOffset_[k] + i)), minusOne),
                            &bits);
          edgeMask |= uint32_t(bits) << (row * kBlockSize + i);
        }
      }
      mask &= edgeMask;
    }
    ++ctx_.stats->partialBlocks;
    ctx_.stats->windows[kStatLevels - 1] += kBlockPixels;
    if (mask) shade(lx, ly, mask);
  }

  void fill(int lx, int ly, int n) {
    ++ctx_.stats->fullWindows;
    for (int by = ly; by < ly + n; by += kBlockSize)
      for (int bx = lx; bx < lx + n; bx += kBlockSize) shade(bx, by, 0xFFFF);
  }

  void shade(int lx, int ly, uint32_t mask) {
    ctx_.stats->fragments += std::popcount(mask);
    const size_t block = size_t(ly >> kBlockLog2) * kBlocksPerTileSide + (lx >> kBlockLog2);
    if constexpr (kShade == ShadeMode::overdraw) {
      countBlock(mask, ctx_.color + block * kColorPerBlock);
    } else {
      shadeBlock(t_, mask, ctx_.originX + lx, ctx_.originY + ly, ctx_.depth + block * kBlockPixels,
                 ctx_.color + block * kColorPerBlock);
    }
  }

  const TriangleSetup& t_;
  const TileContext& ctx_;
  int64_t sX_[E], sY_[E], pos_[E], neg_[E];
  alignas(32) int64_t rowOffset_[E][kBlockSize];
};

void clearTile(const TileWork& w) {
  std::fill(w.depth, w.depth + kTilePixels, w.clearDepth);
  for (int b = 0; b < kTilePixels / kBlockPixels; ++b)
    for (int ch = 0; ch < kColorChannels; ++ch)
      std::fill_n(w.color + b * kColorPerBlock + ch * kBlockPixels, kBlockPixels, w.clearColor[ch]);
}

template <ShadeMode kShade>
void drawLists(const TileWork& w, RasterStats& stats) {
  const TileContext ctx{w.tileX * kTileSize, w.tileY * kTileSize, w.depth, w.color, &stats};
  for (int l = 0; l < w.listCount; ++l) {
    for (uint32_t i = 0; i < w.listSizes[l]; ++i) {
      const TriangleSetup& t = w.setups[w.lists[l][i]];
      // Specialize on the edge count once per triangle (STYLE.md habit 6).
      switch (t.edgeCount) {
        case 3: TriangleRaster<3, kShade>(t, ctx).draw(); break;
        case 4: TriangleRaster<4, kShade>(t, ctx).draw(); break;
        default: TriangleRaster<5, kShade>(t, ctx).draw(); break;
      }
    }
  }
}

void RasterizeTile(const TileWork& w, RasterStats& stats) {
  if (w.clear) clearTile(w);
  if (w.shade == ShadeMode::overdraw)
    drawLists<ShadeMode::overdraw>(w, stats);
  else
    drawLists<ShadeMode::gouraud>(w, stats);
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::raster
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sv::raster {
HWY_EXPORT(RasterizeTile);

void rasterizeTile(const TileWork& work, RasterStats& stats) {
  HWY_DYNAMIC_DISPATCH(RasterizeTile)(work, stats);
}
}  // namespace sv::raster
#endif
