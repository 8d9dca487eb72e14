// Multi-level priority masking (SPEC §4, seeds 000 and 004): which parts of a 64×64 tile are
// already occupied by nearer opaque primitives, at every level of the subdivision.
//
// Primitives arrive in priority order, nearest first. A window is *occupied* (full) when opaque
// primitives drawn so far cover it completely — one primitive at once (a covered window filled
// directly), or several together (four full children make their parent full, propagated upward);
// a pixel when its samples are all covered. A later primitive is dropped from an occupied window at
// any level, and only partial coverage of an empty window continues down, so sub-pixel work is
// done only along the contours of visible primitives. *Touched* windows hold some occupied pixel
// or sample: a covered window that is untouched is filled without looking further down.
//
// The combination with depth (SPEC §4; seeds 000, 004 allow it), for input without a valid priority
// order: a full window also keeps zmax, an upper bound of the depth of every sample in it (exact
// from the depth buffer when a block becomes full, the larger of the children's for a parent, the
// covering triangle's largest depth for a window filled by one), and a triangle whose smallest
// depth in a window is not below that bound is dropped there — hierarchical Z, with the image
// still exactly the Z-buffer's, since depths only ever decrease under the test "less".
//
// Levels are indexed by the window's log2 size: 2 (the 4×4 blocks of the tile kernel) to 6 (the
// tile). A window full at some level makes everything inside it full; its descendants' own bits
// and masks are then left as they were, so that queries for a window reached from above (the
// descent checks each child) read its own bit, and queries for a root window read its ancestors'.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <limits>

#include "raster/framebuffer.h"

namespace sv::raster {

class Occupancy {
 public:
  static constexpr int kMinLevel = kBlockLog2;  // 4×4 blocks
  static constexpr int kMaxLevel = kTileLog2;   // the tile
  static constexpr int kBlocks = kTilePixels / kBlockPixels;

  // Empties the tile. `samples` per pixel: 1, or the anti-aliasing sample count (≤ 64).
  void clear(int samples) {
    std::memset(full_, 0, sizeof(full_));
    std::memset(touched_, 0, sizeof(touched_));
    std::memset(blockInFull_, 0, sizeof(blockInFull_));
    std::fill_n(blockBound_, kBlocks, kNoBound);
    sampleCount_ = samples;
    fullWord_[0] = fullSampleWord(samples, 0);
    fullWord_[1] = fullSampleWord(samples, 1);
  }

  // Whether the window of size 2^level at tile-local pixel (lx, ly) is full — by its own bit only
  // (a window reached by descending from a window that was not full).
  bool full(int level, int lx, int ly) const { return test(full_, level, lx, ly); }
  // Whether it, or a window that contains it, is full (a window where a descent starts).
  bool fullOrInside(int level, int lx, int ly) const {
    if (level == kMinLevel) {  // the flat per-block copy: one test for the kernel's 4×4 roots
      const int b = blockIndex(lx, ly);
      return blockInFull_[b >> 6] >> (b & 63) & 1;
    }
    for (int l = level; l <= kMaxLevel; ++l)
      if (test(full_, l, lx, ly)) return true;
    return false;
  }
  bool touched(int level, int lx, int ly) const { return test(touched_, level, lx, ly); }

  // The occupied pixels of the 4×4 block at (lx, ly), a bit per pixel (lane y·4 + x), for a block
  // that is not full.
  uint32_t pixels(int lx, int ly) const {
    return touched(kMinLevel, lx, ly) ? pixels_[blockIndex(lx, ly)] : 0u;
  }
  // Its occupied samples per pixel (anti-aliasing), in the words of the coverage masks
  // (raster/coverage_masks.h): samples[w][pixel]; nullptr for an untouched block (none).
  const uint32_t (*samples(int lx, int ly) const)[kBlockPixels] {
    return touched(kMinLevel, lx, ly) ? sampleMask_[blockIndex(lx, ly)] : nullptr;
  }

  // Whether the tile-local pixel rectangle [x0, x1] × [y0, y1] (inside the tile) lies wholly in
  // full windows: a primitive inside it is hidden before anything about it is set up.
  bool rectFull(int x0, int y0, int x1, int y1) const {
    return rectFull(kMaxLevel, 0, 0, x0, y0, x1, y1);
  }

  // Marks a window of size 2^level full: covered by one opaque primitive, whose depths there are
  // at most `zmax` (with depth; +∞ for masking alone).
  void markFull(int level, int lx, int ly, float zmax = kNoBound) {
    touch(level, lx, ly);
    set(full_, level, lx, ly);
    zmax_[level - kMinLevel][bitIndex(level, lx, ly)] = zmax;
    coverBlocks(level, lx, ly, zmax);
    propagate(level, lx, ly);
  }

  // The depth bound of the window (the smallest full window holding it), +∞ if none is full.
  float zmaxOver(int level, int lx, int ly) const {
    if (level == kMinLevel) return blockBound_[blockIndex(lx, ly)];
    for (int l = level; l <= kMaxLevel; ++l)
      if (test(full_, l, lx, ly)) return zmax_[l - kMinLevel][bitIndex(l, lx, ly)];
    return kNoBound;
  }

  // A full window has been drawn over entirely again, by depths of at most `z`: its bound is now
  // the smaller of the two.
  void lowerZmax(int level, int lx, int ly, float z) {
    if (!test(full_, level, lx, ly)) return;
    float& bound = zmax_[level - kMinLevel][bitIndex(level, lx, ly)];
    if (!(z < bound)) return;
    bound = z;
    coverBlocks(level, lx, ly, z);
    propagate(level, lx, ly);
  }

  // Whether the rectangle lies in full windows whose depth bounds are at most zmin (a triangle
  // whose depth there is at least zmin is hidden).
  bool rectHidden(int x0, int y0, int x1, int y1, float zmin) const {
    return rectHidden(kMaxLevel, 0, 0, x0, y0, x1, y1, zmin);
  }

  static constexpr float kNoBound = std::numeric_limits<float>::infinity();

  // Adds occupied pixels to the block at (lx, ly) (one sample per pixel). With depth, `depth` is
  // the block's depth buffer (16 values), read once when the block becomes full.
  void addPixels(int lx, int ly, uint32_t mask, const float* depth = nullptr) {
    if (!mask) return;
    const int b = blockIndex(lx, ly);
    if (!touched(kMinLevel, lx, ly)) {
      pixels_[b] = 0;
      touch(kMinLevel, lx, ly);
    }
    if (pixels_[b] == 0xFFFF) return;  // full already (its bound is kept by lowerZmax)
    pixels_[b] = uint16_t(pixels_[b] | mask);
    if (pixels_[b] == 0xFFFF)
      markFull(kMinLevel, lx, ly, depth ? maxOf(depth, kBlockPixels) : kNoBound);
  }

  // Adds occupied samples (anti-aliasing), `mask[w][pixel]` in the coverage masks' words; a pixel
  // whose samples are all occupied becomes an occupied pixel. `depth`: as addPixels, the block's
  // sample planes.
  void addSamples(int lx, int ly, const uint32_t (*mask)[kBlockPixels],
                  const float* depth = nullptr) {
    if (full(kMinLevel, lx, ly)) return;
    uint32_t(*words)[kBlockPixels] = sampleWords(lx, ly);
    uint32_t fullPixels = 0;
    for (int p = 0; p < kBlockPixels; ++p) {
      const uint32_t w0 = words[0][p] |= mask[0][p];
      const uint32_t w1 = words[1][p] |= mask[1][p];
      fullPixels |= uint32_t(w0 == fullWord_[0] && w1 == fullWord_[1]) << p;
    }
    setPixels(lx, ly, fullPixels,
              fullPixels == 0xFFFF && depth ? maxOf(depth, kBlockPixels * sampleCount_) : kNoBound);
  }

  // The pieces of addSamples for a SIMD caller (the tile kernel): the block's occupied-sample
  // words to OR masks into (zeroed when the block is first touched), then the block's occupied
  // pixels as they now are — and, when all 16 are, its depth bound.
  uint32_t (*sampleWords(int lx, int ly))[kBlockPixels] {
    const int b = blockIndex(lx, ly);
    if (!touched(kMinLevel, lx, ly)) {
      pixels_[b] = 0;
      std::memset(sampleMask_[b], 0, sizeof(sampleMask_[b]));
      touch(kMinLevel, lx, ly);
    }
    return sampleMask_[b];
  }
  void setPixels(int lx, int ly, uint32_t pixels, float zmax = kNoBound) {
    const int b = blockIndex(lx, ly);
    pixels_[b] = uint16_t(pixels);
    if (pixels == 0xFFFF) markFull(kMinLevel, lx, ly, zmax);
  }
  const uint32_t* fullWords() const { return fullWord_; }

 private:
  // Window (lx, ly) of size 2^level: bit (ly >> level)·(64 >> level) + (lx >> level).
  static int bitIndex(int level, int lx, int ly) {
    return ((ly >> level) << (kMaxLevel - level)) + (lx >> level);
  }
  static int blockIndex(int lx, int ly) { return bitIndex(kMinLevel, lx, ly); }
  static bool test(const uint64_t (*bits)[kBlocks / 64], int level, int lx, int ly) {
    const int i = bitIndex(level, lx, ly);
    return bits[level - kMinLevel][i >> 6] >> (i & 63) & 1;
  }
  static void set(uint64_t (*bits)[kBlocks / 64], int level, int lx, int ly) {
    const int i = bitIndex(level, lx, ly);
    bits[level - kMinLevel][i >> 6] |= uint64_t(1) << (i & 63);
  }
  bool rectFull(int level, int wx, int wy, int x0, int y0, int x1, int y1) const {
    if (test(full_, level, wx, wy)) return true;
    if (level == kMinLevel || !test(touched_, level, wx, wy)) return false;
    const int h = 1 << (level - 1);
    for (int c = 0; c < 4; ++c) {
      const int cx = wx + (c & 1) * h, cy = wy + (c >> 1) * h;
      if (cx > x1 || cy > y1 || cx + h - 1 < x0 || cy + h - 1 < y0) continue;  // disjoint
      if (!rectFull(level - 1, cx, cy, x0, y0, x1, y1)) return false;
    }
    return true;
  }
  bool rectHidden(int level, int wx, int wy, int x0, int y0, int x1, int y1, float zmin) const {
    if (test(full_, level, wx, wy) && zmin >= zmax_[level - kMinLevel][bitIndex(level, wx, wy)])
      return true;
    if (level == kMinLevel || !test(touched_, level, wx, wy)) return false;
    const int h = 1 << (level - 1);
    for (int c = 0; c < 4; ++c) {
      const int cx = wx + (c & 1) * h, cy = wy + (c >> 1) * h;
      if (cx > x1 || cy > y1 || cx + h - 1 < x0 || cy + h - 1 < y0) continue;
      if (!rectHidden(level - 1, cx, cy, x0, y0, x1, y1, zmin)) return false;
    }
    return true;
  }
  // After a window's bound changed: parents whose four children are full become (or stay) full,
  // bounded by the largest of the children's bounds.
  void propagate(int level, int lx, int ly) {
    for (int l = level; l < kMaxLevel; ++l) {
      const int parentX = lx >> (l + 1) << (l + 1), parentY = ly >> (l + 1) << (l + 1);
      const int h = 1 << l;
      float bound = 0;
      for (int c = 0; c < 4; ++c) {
        const int cx = parentX + (c & 1) * h, cy = parentY + (c >> 1) * h;
        if (!test(full_, l, cx, cy)) return;
        bound = std::max(bound, zmax_[l - kMinLevel][bitIndex(l, cx, cy)]);
      }
      float& parent = zmax_[l + 1 - kMinLevel][bitIndex(l + 1, parentX, parentY)];
      if (test(full_, l + 1, parentX, parentY)) {
        if (!(bound < parent)) return;  // no tighter than it was
      } else {
        set(full_, l + 1, parentX, parentY);
      }
      parent = bound;
      coverBlocks(l + 1, parentX, parentY, bound);
    }
  }
  // The flat per-block copies: the blocks of a full window (level, lx, ly) lie in a full window,
  // bounded by at most z (+∞: masking alone, no bounds to keep).
  void coverBlocks(int level, int lx, int ly, float z) {
    const int side = 1 << (level - kMinLevel);
    const int bx = (lx >> level << level) >> kMinLevel, by = (ly >> level << level) >> kMinLevel;
    const bool bounded = z < kNoBound;
    for (int y = by; y < by + side; ++y) {
      // A row of up to 16 blocks lies in one 64-bit word (16 blocks a row, 4 rows a word).
      const int b = y * (kTileSize >> kMinLevel) + bx;
      blockInFull_[b >> 6] |= ((side == 16 ? 0xFFFFull : (uint64_t(1) << side) - 1)) << (b & 63);
      if (bounded)
        for (int x = 0; x < side; ++x) blockBound_[b + x] = std::min(blockBound_[b + x], z);
    }
  }
  static float maxOf(const float* v, int n) {
    float m = v[0];
    for (int i = 1; i < n; ++i) m = std::max(m, v[i]);
    return m;
  }
  // The window and every window containing it hold something occupied (a touched window's
  // ancestors are all touched already).
  void touch(int level, int lx, int ly) {
    for (int l = level; l <= kMaxLevel && !test(touched_, l, lx, ly); ++l) set(touched_, l, lx, ly);
  }

  static constexpr int kLevelCount = kMaxLevel - kMinLevel + 1;
  uint64_t full_[kLevelCount][kBlocks / 64];
  uint64_t touched_[kLevelCount][kBlocks / 64];
  // Valid for touched blocks only (cleared when a block is first touched).
  uint16_t pixels_[kBlocks];
  float zmax_[kLevelCount][kBlocks];  // valid for full windows
  // Per block: inside some full window; the smallest bound of the full windows holding it.
  uint64_t blockInFull_[kBlocks / 64];
  float blockBound_[kBlocks];
  uint32_t sampleMask_[kBlocks][2][kBlockPixels];
  int sampleCount_ = 1;
  uint32_t fullWord_[2] = {1, 0};
};

}  // namespace sv::raster
