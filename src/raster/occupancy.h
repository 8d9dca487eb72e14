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
// Levels are indexed by the window's log2 size: 2 (the 4×4 blocks of the tile kernel) to 6 (the
// tile). A window full at some level makes everything inside it full; its descendants' own bits
// and masks are then left as they were, so that queries for a window reached from above (the
// descent checks each child) read its own bit, and queries for a root window read its ancestors'.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>

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
    sampleCount_ = samples;
    fullWord_[0] = samples >= 32 ? ~0u : (1u << samples) - 1;
    fullWord_[1] = samples > 32 ? ~0u : 0u;
  }

  // Whether the window of size 2^level at tile-local pixel (lx, ly) is full — by its own bit only
  // (a window reached by descending from a window that was not full).
  bool full(int level, int lx, int ly) const { return test(full_, level, lx, ly); }
  // Whether it, or a window that contains it, is full (a window where a descent starts).
  bool fullOrInside(int level, int lx, int ly) const {
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
  // (raster/coverage_masks.h): samples[w][pixel]. All zero for an untouched block.
  void samples(int lx, int ly, uint32_t out[2][kBlockPixels]) const {
    if (!touched(kMinLevel, lx, ly)) {
      std::memset(out, 0, sizeof(uint32_t) * 2 * kBlockPixels);
      return;
    }
    std::memcpy(out, sampleMask_[blockIndex(lx, ly)], sizeof(uint32_t) * 2 * kBlockPixels);
  }

  // Whether the tile-local pixel rectangle [x0, x1] × [y0, y1] (inside the tile) lies wholly in
  // full windows: a primitive inside it is hidden before anything about it is set up.
  bool rectFull(int x0, int y0, int x1, int y1) const {
    return rectFull(kMaxLevel, 0, 0, x0, y0, x1, y1);
  }

  // Marks a window of size 2^level full: covered by one opaque primitive.
  void markFull(int level, int lx, int ly) {
    touch(level, lx, ly);
    for (int l = level; l <= kMaxLevel; ++l) {
      set(full_, l, lx, ly);
      if (l == kMaxLevel) return;
      // The parent is full when its four children are.
      const int parentX = lx >> (l + 1) << (l + 1), parentY = ly >> (l + 1) << (l + 1);
      const int h = 1 << l;
      if (!(test(full_, l, parentX, parentY) && test(full_, l, parentX + h, parentY) &&
            test(full_, l, parentX, parentY + h) && test(full_, l, parentX + h, parentY + h)))
        return;
    }
  }

  // Adds occupied pixels to the block at (lx, ly) (one sample per pixel).
  void addPixels(int lx, int ly, uint32_t mask) {
    if (!mask) return;
    const int b = blockIndex(lx, ly);
    if (!touched(kMinLevel, lx, ly)) {
      pixels_[b] = 0;
      touch(kMinLevel, lx, ly);
    }
    pixels_[b] = uint16_t(pixels_[b] | mask);
    if (pixels_[b] == 0xFFFF) markFull(kMinLevel, lx, ly);
  }

  // Adds occupied samples (anti-aliasing), `mask[w][pixel]` in the coverage masks' words; a pixel
  // whose samples are all occupied becomes an occupied pixel.
  void addSamples(int lx, int ly, const uint32_t (*mask)[kBlockPixels]) {
    const int b = blockIndex(lx, ly);
    if (!touched(kMinLevel, lx, ly)) {
      pixels_[b] = 0;
      std::memset(sampleMask_[b], 0, sizeof(sampleMask_[b]));
      touch(kMinLevel, lx, ly);
    }
    uint32_t fullPixels = 0;
    for (int p = 0; p < kBlockPixels; ++p) {
      const uint32_t w0 = sampleMask_[b][0][p] |= mask[0][p];
      const uint32_t w1 = sampleMask_[b][1][p] |= mask[1][p];
      fullPixels |= uint32_t(w0 == fullWord_[0] && w1 == fullWord_[1]) << p;
    }
    pixels_[b] = uint16_t(fullPixels);
    if (fullPixels == 0xFFFF) markFull(kMinLevel, lx, ly);
  }

  int sampleCount() const { return sampleCount_; }

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
  // The window and every window containing it hold something occupied.
  void touch(int level, int lx, int ly) {
    for (int l = level; l <= kMaxLevel; ++l) set(touched_, l, lx, ly);
  }

  static constexpr int kLevelCount = kMaxLevel - kMinLevel + 1;
  uint64_t full_[kLevelCount][kBlocks / 64];
  uint64_t touched_[kLevelCount][kBlocks / 64];
  // Valid for touched blocks only (cleared when a block is first touched).
  uint16_t pixels_[kBlocks];
  uint32_t sampleMask_[kBlocks][2][kBlockPixels];
  int sampleCount_ = 1;
  uint32_t fullWord_[2] = {1, 0};
};

}  // namespace sv::raster
