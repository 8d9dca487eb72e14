// The descent (Highway, per target): one triangle in one tile by recursive 2×2 subdivision with
// coverage functions down to 4×4 leaves, whose pixels go to the block operations.
//
// Based on: SPEC §3.1 (seed 000 eqs. 2–5), §3.2 (eqs. 6–9), §3.3 (seed 004 eq. 14), §3.5, §4;
// Mesa llvmpipe's lp_rast_tri_tmp.h and Abrash 2009 (Larrabee) for the trivial accept/reject
// formulation of the same test.
//
// Symbols. For an edge e(px, py) = c + sX·px + sY·py (setup.h), a window of n×n pixels is kept by
// the value tl of e at the centre of its top-left pixel. Seed 000's coverage function is
//     d = e(x_c, y_c) + ε,   ε = (|A|·a + |B|·b)/2,   a = b = n − 1 (α = β = 0: point sampling)
// — the largest value of e over the window's pixel centres. With sX⁺ = max(sX, 0) and
// sX⁻ = min(sX, 0):
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
//
// Per-target include guard (Highway's convention for -inl.h files): included by tile_kernel.cpp,
// once per SIMD target, so that everything here inlines into the kernel.
#if defined(SV_RASTER_DESCENT_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef SV_RASTER_DESCENT_INL_H_
#undef SV_RASTER_DESCENT_INL_H_
#else
#define SV_RASTER_DESCENT_INL_H_
#endif

#include <cstring>
#include <limits>

#include "raster/block_ops-inl.h"
#include "raster/material_blocks-inl.h"

HWY_BEFORE_NAMESPACE();
namespace sv::raster {
namespace HWY_NAMESPACE {

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
    // themselves: a scan of the box's blocks, each tested in SIMD, beats any descent there, up to
    // 32 px and not beyond (docs/performance.md, "The descent").
    constexpr int kScanExtent = 32;
    const int extent = std::max(x1 - x0, y1 - y0) + 1;
    const int log2n = extent <= kScanExtent
                          ? kBlockLog2
                          : std::max(kBlockLog2, int(std::bit_width(unsigned(extent - 1))) - 1);
    const int n = 1 << log2n;
    // Past kSpanExtent pixels, block rows (spans) where they apply. From 16 px: from 8, 30k × 30 px
    // was ×1.03 slower; from 4, 100k × 10 px ×1.14; the scan up to 32 px had left 30k × 100 px ×0.95
    // behind (docs/performance.md, "Fill and texture against the roofline").
    constexpr int kSpanExtent = 16;
    if constexpr (kSpans) {
      if (!occ_ && extent > kSpanExtent) return spans(x0, y0, x1, y1);
    }
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
      const bool owns = geometry::ownsBoundary(a, b);  // the fill rule's −1, taken back out
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

  // Triangles past kSpanExtent walked as rows of 4×4 blocks (issue 37), where nothing needs
  // the windows above a block — no masking (occupancy is kept per window), no anti-aliasing, no
  // debug view that shows them: every block of a row of the box is classified against each edge
  // at once, one SIMD lane a block — wholly outside an edge (dropped), inside every edge (filled),
  // or crossed (a leaf, testing only the edges that cross it). The tests are the descent's at its
  // last window level, so the pixels are the same, and a triangle writes a pixel once whatever
  // order its blocks come in: the image is the descent's, bit for bit (tests/golden). What the
  // descent spent on its branches above the blocks is saved: tris 10k × 1000 px ×0.80, textured
  // ×0.89 (docs/performance.md, "Fill against the roofline"). A row's planes are evaluated once
  // for all its blocks (runBases) and its full blocks drawn in runs without a coverage test.
  static constexpr bool kSpans = !kAA && kOp != PixelOp::levels && kOp != PixelOp::overdraw;

  // Out of line: inlined into draw, it slowed the small triangles' path beside it (×1.04–1.09).
  HWY_NOINLINE void spans(int x0, int y0, int x1, int y1) {
    const int bx0 = x0 >> kBlockLog2, bx1 = x1 >> kBlockLog2;
    const int by0 = y0 >> kBlockLog2, by1 = y1 >> kBlockLog2;
    const int columns = bx1 - bx0 + 1;  // lane j: block column bx0 + j
    const unsigned live = (1u << columns) - 1;
    const hn::CappedTag<T, kBlocksPerTileSide> d;
    const size_t lanes = hn::Lanes(d);
    const auto zero = hn::Zero(d);
    // Per edge, each lane's offset from the row's first block, sX·4·j, within the box's blocks
    // (whose values the descent's budget covers); the lanes past them up to a whole vector read 0,
    // their bits dropped by `live`. Only those are written: zeroing the whole array was a 320-byte
    // memset per call.
    const int padded = int(hwy::RoundUpTo(size_t(columns), lanes));
    alignas(64) T step[kMaxEdges][kBlocksPerTileSide];
    for (int k = 0; k < E; ++k)
      for (int j = 0; j < padded; ++j) step[k][j] = j < columns ? sX_[k] * T(j * kBlockSize) : T(0);
    for (int by = by0; by <= by1; ++by) {
      const int ly = by << kBlockLog2;
      ctx_.stats->windows[statLevel(kBlockLog2)] += uint64_t(columns);
      T rowTl[kMaxEdges];
      unsigned out = 0, crossed[kMaxEdges] = {};
      for (int k = 0; k < E; ++k) {
        const auto& e = t_.edges[k];
        rowTl[k] = T(e.c + e.stepX() * (ctx_.originX + (bx0 << kBlockLog2)) +
                     e.stepY() * (ctx_.originY + ly));
        const auto base = hn::Set(d, rowTl[k]);
        const auto dMax = hn::Set(d, maxOffset(k, T(kBlockSize - 1)));
        const auto dMin = hn::Set(d, minOffset(k, T(kBlockSize - 1)));
        for (size_t i = 0; i < size_t(columns); i += lanes) {
          const auto tl = hn::Add(base, hn::LoadU(d, step[k] + i));
          out |= laneBits(d, hn::Lt(hn::Add(tl, dMax), zero), i);
          crossed[k] |= laneBits(d, hn::Lt(hn::Add(tl, dMin), zero), i);
        }
      }
      unsigned anyCrossed = 0;
      for (int k = 0; k < E; ++k) anyCrossed |= crossed[k];
      const unsigned in = live & ~out;
      if (!in) continue;
      // The planes' bases of the row's blocks from its first drawn one, in one vector expression
      // each (runBases) rather than one per block.
      const int first = std::countr_zero(in), count = std::bit_width(in) - first;
      alignas(64) float base[kPlaneCount][kBlocksPerTileSide];
      if constexpr (kRowBases)
        runBases(t_, planeLanes_, ctx_.originX + ((bx0 + first) << kBlockLog2), ctx_.originY + ly,
                 count, kOp == PixelOp::visibility ? 1 : kPlaneCount, base);
      // The row's full blocks first, in runs (as plainFill's), then its crossed ones.
      const unsigned full = in & ~anyCrossed;
      if (full) {
        ctx_.stats->fullWindows += uint64_t(std::popcount(full));
        drawLevel_ = kBlockLog2;
        if constexpr (kRowBases) {
          for (unsigned b = full; b;) {
            const int j = std::countr_zero(b), run = std::countr_one(b >> j);
            b &= ~(((1u << run) - 1) << j);
            fullRun((bx0 + j) << kBlockLog2, ly, run, &base[0][j - first]);
          }
        } else {
          for (unsigned b = full; b; b &= b - 1)
            shade((bx0 + std::countr_zero(b)) << kBlockLog2, ly, 0xFFFF);
        }
      }
      for (unsigned b = in & anyCrossed; b; b &= b - 1) {
        const int j = std::countr_zero(b);
        unsigned active = 0;
        T tl[kMaxEdges];
        for (int k = 0; k < E; ++k) {
          active |= ((crossed[k] >> j) & 1u) << k;
          tl[k] = rowTl[k] + step[k][j];
        }
        leaf((bx0 + j) << kBlockLog2, ly, tl, active, kRowBases ? &base[0][j - first] : nullptr);
      }
    }
  }

  // Whether spans hands the blocks their planes' bases from one evaluation per row (runBases):
  // the operations whose block functions take them.
  static constexpr bool kRowBases = kOp == PixelOp::gouraud || kOp == PixelOp::visibility;

  // A run of `count` full blocks in a row from (lx, ly), base[p · kBlocksPerTileSide + j] holding
  // plane p at block j's top-left pixel (runBases): each block's depth test and colour or
  // visibility with no coverage test. The same operations per pixel as shade's, so the same image.
  void fullRun(int lx, int ly, int count, const float* base) {
    const size_t first = tileBlock(lx, ly);
    int hidden = 0;
    for (int j = 0; j < count; ++j) {
      const size_t block = first + size_t(j);
      if constexpr (kOp == PixelOp::visibility)
        hidden += visibleBlockAt<true>(planeLanes_, base[j], 0xFFFF, id_,
                                       ctx_.depth + block * kBlockPixels,
                                       ctx_.visible + block * kBlockPixels);
      else
        hidden += gouraudBlock<true>(planeLanes_, base + j, kBlocksPerTileSide, 0xFFFF,
                                     ctx_.depth + block * kBlockPixels,
                                     ctx_.color + block * kColorPerBlock);
    }
    ctx_.stats->fragments += uint64_t(count) * kBlockPixels;
    ctx_.stats->hiddenFragments += uint64_t(hidden);
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
  // all 16 pixel centres tested at once in SIMD lanes. Always inlined: called from spans too, the
  // compiler took it out of draw's scan of small triangles (layers ×1.15, tris 100k × 10 ×1.08).
  // `base`: the planes' bases at the block, base[p · kBlocksPerTileSide] (spans), or nullptr.
  HWY_INLINE void leaf(int lx, int ly, const T* tl, unsigned active, const float* base = nullptr) {
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
    if constexpr (kRowBases) {
      if (base) shadeFromRow(lx, ly, mask, base);
      else shade(lx, ly, mask);
    } else {
      shade(lx, ly, mask);
    }
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
    // Row entries are read by vector gathers, which measured faster than scalar loads of
    // SIMD-computed entries (docs/performance.md, "Anti-aliasing").
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

  // shade for a crossed block of a row (spans, kRowBases), its planes' bases from the row's:
  // base[p · kBlocksPerTileSide] (runBases). A function of its own, so that the scan's shade keeps
  // no test for it.
  void shadeFromRow(int lx, int ly, uint32_t mask, const float* base) {
    ctx_.stats->fragments += std::popcount(mask);
    const size_t block = tileBlock(lx, ly);
    if constexpr (kOp == PixelOp::visibility)
      ctx_.stats->hiddenFragments +=
          visibleBlockAt(planeLanes_, base[kDepth], mask, id_, ctx_.depth + block * kBlockPixels,
                         ctx_.visible + block * kBlockPixels);
    else
      ctx_.stats->hiddenFragments +=
          gouraudBlock(planeLanes_, base, kBlocksPerTileSide, mask,
                       ctx_.depth + block * kBlockPixels, ctx_.color + block * kColorPerBlock);
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

}  // namespace HWY_NAMESPACE
}  // namespace sv::raster
HWY_AFTER_NAMESPACE();

#endif  // SV_RASTER_DESCENT_INL_H_
