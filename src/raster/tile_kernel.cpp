// The tile kernel: one tile's lists of triangles drawn in order — cleared, each triangle through
// the descent (descent-inl.h) and its block operations (block_ops-inl.h, material_blocks-inl.h),
// the deferred pixels shaded (deferred_shading-inl.h), the passes after the opaque polygons
// (TileWork::afterOpaque), hybrid masking woken where it pays (hybrid_wake-inl.h). Compiled once
// per SIMD target (Highway: this file and the -inl.h files it includes form one unit per target,
// so nothing loses inlining) and dispatched once per tile.
//
// Based on: SPEC §3 (recursive subdivision), §4 (Z-buffer, priority masking), §1 (visibility
// apart from shading), §5 (samples).

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/tile_kernel.cpp"
// clang-format off: foreach_target.h first, the per-target -inl.h headers after it
#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"
// clang-format on

#include <algorithm>
#include <cstddef>
#include <cstring>

#include "hwy/cache_control.h"
#include "raster/deferred_shading-inl.h"
#include "raster/descent-inl.h"
#include "raster/framebuffer.h"
#include "raster/hybrid_wake-inl.h"
#include "raster/occupancy.h"
#include "raster/rasterizer.h"

HWY_BEFORE_NAMESPACE();
namespace sv::raster {
namespace HWY_NAMESPACE {

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
  // One plane's worth, copied whole (two or three vector stores), not three fills of 16 values
  // per plane (docs/performance.md, "Anti-aliasing").
  alignas(64) uint16_t plane[kColorPerBlock];
  for (int ch = 0; ch < kColorChannels; ++ch)
    std::fill_n(plane + ch * kBlockPixels, kBlockPixels, w.clearColor[ch]);
  for (int b = 0; b < planes; ++b)
    std::memcpy(w.color + size_t(b) * kColorPerBlock, plane, sizeof(plane));
}

// The tile's context for the kernel's steps.
TileContext makeTileContext(const TileWork& w, RasterStats& stats, bool deferred) {
  return TileContext{
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
      w.shade == ShadeMode::overdraw || w.masking == Masking::none ? nullptr : w.occupancy,
      w.masking == Masking::hybrid};
}

// TileTarget::translucentDepth for the passes after the opaque surfaces, where one wants it: the
// tile's depth planes copied to scratch and the batch's translucent triangles drawn into them
// (depth-tested and written, colour thrown away) — the nearest translucent surface in front of
// each sample's opaque one. nullptr where no pass wants it.
template <bool kAA>
const float* translucentDepth(const TileWork& w) {
  if (!w.translucentDepth || !w.attributes) return nullptr;
  bool wanted = false;
  for (const TilePass* pass : w.afterOpaque)
    wanted |= pass->wantsTranslucentDepth(w.tileX, w.tileY);
  if (!wanted) return nullptr;
  const int samples = w.coverage ? w.coverage->samples : 1;
  std::copy_n(w.depth, size_t(kTilePixels) * size_t(samples), w.translucentDepth);
  RasterStats uncounted;  // (the triangles are counted when they are drawn)
  TileContext ctx = makeTileContext(w, uncounted, false);
  ctx.depth = w.translucentDepth;
  ctx.color = w.translucentColor;
  ctx.occupancy = nullptr;
  for (int l = 0; l < w.listCount; ++l)
    for (uint32_t i = 0; i < w.listSizes[l]; ++i) {
      const uint32_t id = w.lists[l][i];
      const shade::MaterialShading* m = w.attributes[id].material;
      if (m && m->alpha == shade::AlphaUse::blend)
        drawTriangle<PixelOp::gouraud, kAA>(w.setups[id], ctx);
    }
  return w.translucentDepth;
}

// The tile's opaque surfaces are all in: TileWork::afterOpaque's passes, once — before its first
// translucent triangle (`beforeTranslucent`: with the translucent surfaces' depth, for the passes
// that want it), or after its last triangle.
template <bool kAA>
void afterOpaque(const TileWork& w, bool beforeTranslucent) {
  if (w.afterOpaque.empty() || !w.opaqueDone || *w.opaqueDone) return;
  *w.opaqueDone = true;
  TileTarget target{w.tileX, w.tileY, w.depth, w.color, w.worker};
  if (beforeTranslucent) target.translucentDepth = translucentDepth<kAA>(w);
  for (TilePass* pass : w.afterOpaque) pass->drawTile(target);
}

// The tile's last batch is drawn: the passes after the opaque surfaces over its translucent ones.
void overTranslucent(const TileWork& w) {
  const TileTarget target{w.tileX, w.tileY, w.depth, w.color, w.worker};
  for (TilePass* pass : w.afterOpaque) pass->overTranslucent(target);
}

// Object-space culling with masking (TileWork::listObjects): the object last tested, and whether
// it was hidden. A hidden object stays hidden (occupancy only grows and depth bounds only fall),
// so the answer holds across lists.
struct ObjectCulling {
  uint32_t lastObject = kNoObject;
  bool hidden = false;

  // The entries of list `objects` from i on to skip unread: the rest of a hidden object's run
  // (counted as occluded triangles), or none.
  uint32_t skip(const TileWork& w, const Occupancy& occupancy, const uint32_t* objects,
                uint32_t size, uint32_t i, RasterStats& stats) {
    const uint32_t object = objects[i];
    if (object == kNoObject) return 0;
    if (object != lastObject) {
      lastObject = object;
      hidden = objectHidden(occupancy, w.objects[object], w.tileX, w.tileY, w.masking);
      stats.occludedObjects += hidden;
    }
    if (!hidden) return 0;
    uint32_t end = i + 1;
    while (end < size && objects[end] == object) ++end;
    stats.occludedTriangles += end - i;
    return end - i;
  }
};

// Setup records are read in bin order, scattered over the batch: fetch a few ahead, the loop is
// otherwise bound by their cache misses (2 ahead measures the same as 1 and better than 4 or 8).
constexpr uint32_t kPrefetchDistance = 2;
static_assert(offsetof(AttributeSetup, planes) == sizeof(void*) && alignof(AttributeSetup) == 64);

template <ShadeMode kShade>
HWY_INLINE void prefetchRecords(const TileWork& w, uint32_t ahead, bool wideRecords) {
  const char* next = reinterpret_cast<const char*>(w.setups + ahead);
  for (size_t line = 0; line < sizeof(TriangleSetup); line += 64) hwy::Prefetch(next + line);
  // Pixel shading's record sits at the same index (TileWork::attributes): its first line holds the
  // material and the texture planes; the second the rest, requested while the materials seen last
  // read any of it.
  if constexpr (kShade == ShadeMode::material) {
    const char* record = reinterpret_cast<const char*>(w.attributes + ahead);
    hwy::Prefetch(record);
    if (wideRecords) hwy::Prefetch(record + 64);
  }
}

// One triangle of a pixel-shaded frame (ShadeMode::material): with a material, shaded per pixel —
// deferred at one sample if opaque (its winning pixels recorded, and the triangle in `winners`);
// else plain Gouraud. A translucent one first has the deferred pixels shaded and the passes after
// the opaque surfaces run: blending reads the colour behind. `pending`: some pixel records a
// triangle not yet shaded.
template <bool kAA>
HWY_INLINE void drawShadedTriangle(const TileWork& w, const TileContext& ctx,
                                   const TileContext& use, uint32_t id, bool boxTested,
                                   WinnerList& winners, bool& pending) {
  const TriangleSetup& t = w.setups[id];
  const AttributeSetup& a = w.attributes[id];
  const shade::AlphaUse alpha = a.material ? a.material->alpha : shade::AlphaUse::opaque;
  if (!kAA && alpha == shade::AlphaUse::opaque) {
    RasterStats& stats = *ctx.stats;
    const uint64_t fragments = stats.fragments, hidden = stats.hiddenFragments;
    drawTriangle<PixelOp::visibility, false>(t, use, nullptr, id, boxTested);
    if (stats.fragments - fragments > stats.hiddenFragments - hidden)
      winners.add(id, std::max(t.minX - ctx.originX, 0), std::max(t.minY - ctx.originY, 0),
                  std::min(t.maxX - ctx.originX, kTileSize - 1),
                  std::min(t.maxY - ctx.originY, kTileSize - 1));
    pending = true;
    return;
  }
  if (alpha == shade::AlphaUse::blend) {
    if (pending) shadeVisible(ctx);
    pending = false;
    afterOpaque<kAA>(w, true);
  }
  if (a.material)
    drawTriangle<PixelOp::material, kAA>(t, use, &a, kNoTriangle, boxTested);
  else
    drawTriangle<PixelOp::gouraud, kAA>(t, use, nullptr, kNoTriangle, boxTested);
}

template <ShadeMode kShade, bool kAA>
void drawLists(const TileWork& w, RasterStats& stats) {
  // Pixel shading at one sample is deferred: opaque triangles only record the winner per pixel.
  constexpr bool kDeferred = kShade == ShadeMode::material && !kAA;
  TileContext ctx = makeTileContext(w, stats, kDeferred);
  WinnerList winners;
  if (kDeferred) ctx.winners = &winners;
  alignas(64) float clearPlanes[64 * kBlockPixels];
  if (w.sums) {
    std::fill_n(clearPlanes, ctx.samples * kBlockPixels, w.clearDepth);
    ctx.sums = w.sums;
    ctx.clearPlanes = clearPlanes;
    for (int ch = 0; ch < kColorChannels; ++ch) ctx.clearColor[ch] = w.clearColor[ch];
  }
  uint64_t entries = 0, entriesDone = 0;  // the tile's list entries, and those drawn so far
  for (int l = 0; l < w.listCount; ++l) entries += w.listSizes[l];
  HybridWake hybrid(ctx, ctx.occupancy && ctx.hybrid && w.clear && !w.debugOccupancy, entries,
                    w.clearDepth, stats);
  ObjectCulling culling;
  bool pending = false;  // some pixel records a triangle not yet shaded
  const shade::MaterialShading* lastMaterial = nullptr;
  bool wideRecords = true;
  for (int l = 0; l < w.listCount; ++l) {
    const uint32_t* list = w.lists[l];
    const uint32_t size = w.listSizes[l];
    const uint32_t* objects = ctx.occupancy && w.listObjects ? w.listObjects[l] : nullptr;
    const Binner::Box* boxes =
        ctx.occupancy && !ctx.hybrid && w.listBoxes ? w.listBoxes[l] : nullptr;
    for (uint32_t i = 0; i < size; ++i, ++entriesDone) {
      if (objects && hybrid.awake())
        if (const uint32_t skip = culling.skip(w, *ctx.occupancy, objects, size, i, stats)) {
          entriesDone += skip - 1;
          i += skip - 1;
          continue;
        }
      if (boxes && boxHidden<kAA>(ctx, boxes[i].minX, boxes[i].minY, boxes[i].maxX, boxes[i].maxY))
        continue;
      if (i + kPrefetchDistance < size)
        prefetchRecords<kShade>(w, list[i + kPrefetchDistance], wideRecords);
      const uint64_t fragmentsBefore = stats.fragments, hiddenBefore = stats.hiddenFragments;
      if constexpr (kShade == ShadeMode::material) {
        const AttributeSetup& a = w.attributes[list[i]];
        if (a.material != lastMaterial) {
          lastMaterial = a.material;
          // Triangles shaded as they are drawn (anti-aliased, or not opaque) read every plane
          // (computeAttributeLanes); deferred ones only those their material uses.
          wideRecords =
              a.material &&
              (!kDeferred || a.material->alpha != shade::AlphaUse::opaque ||
               AttributeSetup::readsSecondLine(shade::attributesUsed(*a.material, *w.environment)));
        }
        drawShadedTriangle<kAA>(w, ctx, hybrid.context(), list[i], boxes != nullptr, winners,
                                pending);
      } else {
        constexpr PixelOp op = kShade == ShadeMode::overdraw ? PixelOp::overdraw
                               : kShade == ShadeMode::levels ? PixelOp::levels
                                                             : PixelOp::gouraud;
        drawTriangle<op, kAA>(w.setups[list[i]], hybrid.context(), nullptr, kNoTriangle,
                              boxes != nullptr);
      }
      hybrid.afterTriangle(fragmentsBefore, hiddenBefore, entriesDone);
    }
  }
  if (pending) shadeVisible(ctx);
  hybrid.finish(w.lastBatch);
  if (w.lastBatch) {
    afterOpaque<kAA>(w, false);
    overTranslucent(w);
  }
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
