// Hybrid masking's wake policy (Highway, per target): a tile starts as the plain Z-buffer and
// masks once the depth test has hidden enough (docs/hidden-surfaces.md).
//
// Per-target include guard (Highway's convention for -inl.h files): included by tile_kernel.cpp,
// once per SIMD target, so that everything here inlines into the kernel.
#if defined(SV_RASTER_HYBRID_WAKE_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef SV_RASTER_HYBRID_WAKE_INL_H_
#undef SV_RASTER_HYBRID_WAKE_INL_H_
#else
#define SV_RASTER_HYBRID_WAKE_INL_H_
#endif

#include <cstring>

#include "raster/kernel_common-inl.h"

HWY_BEFORE_NAMESPACE();
namespace sv::raster {
namespace HWY_NAMESPACE {

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

// Hybrid masking pays only where triangles arrive behind what is drawn; elsewhere (one layer, or
// back-to-front input) its marking and checks are pure cost. So a tile starts as the plain
// Z-buffer (`plain`: the context without occupancy) and wakes when the depth test has hidden
// kWakeWork: pixels that passed none of their samples, a triangle hidden whole counting at least
// kHiddenTriangleWork (its traversal costs that much however few pixels it has, and culling it
// whole is what masking does best): the occupancy is rebuilt from the depth buffer and masking
// runs from there on — if at least a quarter of the tile's triangles are still to come: the
// rebuild reads the whole depth buffer, which a few remaining triangles do not repay (random
// order at D = 2 reaches kWakeWork near the end of a tile's list, and waking there made the frame
// slower than the Z-buffer's; docs/hidden-surfaces.md). The image is the Z-buffer's either way;
// only the work differs. The first batch's pass over a tile starts so; one that ends asleep wakes
// before the next batch, whose object culling before setup reads the occupancy (finish). Not
// priority masking: its order may overrule depth — stated priorities — which the Z-buffer would
// not honour.
class HybridWake {
 public:
  // `ctx`: the tile's context with its occupancy; `asleep`: whether the tile starts as the plain
  // Z-buffer (hybrid masking, the batch clears the tile, no occupancy view); `entries`: the
  // tile's list entries in all; `clearDepth`: what occupyFromDepth counts as empty.
  HybridWake(const TileContext& ctx, bool asleep, uint64_t entries, float clearDepth,
             RasterStats& stats)
      : ctx_(ctx), plain_(ctx), entries_(entries), clearDepth_(clearDepth), stats_(stats) {
    plain_.occupancy = nullptr;
    use_ = asleep ? &plain_ : &ctx_;
  }
  // The context triangles are drawn with: the plain one while asleep.
  const TileContext& context() const { return *use_; }
  bool awake() const { return use_ == &ctx_; }
  // After a triangle drawn at entry `entriesDone`, with the fragment counts as they were before
  // it.
  void afterTriangle(uint64_t fragments, uint64_t hidden, uint64_t entriesDone) {
    if (awake()) return;
    const uint64_t drawn = stats_.fragments - fragments;
    hidden = stats_.hiddenFragments - hidden;
    hiddenWork_ += drawn > 0 && hidden == drawn ? std::max(hidden, kHiddenTriangleWork) : hidden;
    if (hiddenWork_ >= kWakeWork && 4 * (entries_ - entriesDone) >= entries_) wake();
  }
  // After the tile's lists: a tile still asleep wakes unless this was the frame's last batch.
  void finish(bool lastBatch) {
    if (!awake() && !lastBatch) wake();
  }

 private:
  static constexpr uint64_t kWakeWork = kTilePixels / 2, kHiddenTriangleWork = 64;
  void wake() {
    occupyFromDepth(ctx_, clearDepth_);
    use_ = &ctx_;
    ++stats_.hybridWoken;
  }

  const TileContext& ctx_;
  TileContext plain_;
  const TileContext* use_;
  uint64_t entries_, hiddenWork_ = 0;
  float clearDepth_;
  RasterStats& stats_;
};

}  // namespace HWY_NAMESPACE
}  // namespace sv::raster
HWY_AFTER_NAMESPACE();

#endif  // SV_RASTER_HYBRID_WAKE_INL_H_
