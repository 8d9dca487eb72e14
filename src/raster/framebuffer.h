// The frame buffer the rasterizer writes: depth and linear colour, stored tile by tile.
//
// Layout. The raster is cut into 64×64-pixel tiles (the level-6 windows of the quadtree over the
// enclosing 2^n square, SPEC §2 "non-power-of-two rasters"); tiles that stick out of the raster are
// stored whole and cropped on output. Inside a tile, 4×4-pixel blocks are stored one after the
// other in row-major block order, and inside a block the 16 pixels in row-major order — so a block,
// the rasterizer's leaf, is one contiguous run of 16 values, one or a few SIMD vectors.
// Colour is planar per block (16 R, 16 G, 16 B, as uint16 linear light 0…65535), so the kernels
// never interleave; output applies gamma through look-up tables (SPEC §8). With N samples per pixel
// (anti-aliasing, SPEC §5) a block holds N such *sample planes* one after the other: plane s is the
// 16 pixels' sample s, laid out exactly as a 1-sample block. The kernel then tests depth and writes
// colour one plane — 16 pixels — per vector, and the resolve sums the planes. Memory per pixel: N ×
// (4 bytes of depth + 6 of colour). Colour sums (TileWork::sums): where every sample is written at
// most once (priority masking, opaque), a pixel's colour is kept instead as the sum of its N
// samples' 16-bit values, 3 int32 per pixel laid out as one plane (block by block: 16 R, 16 G,
// 16 B) — what the resolve would have summed, so the image is the same bit for bit.
#pragma once

#include <cstddef>
#include <cstdint>

#include "hwy/aligned_allocator.h"

namespace sv::raster {

inline constexpr int kTileLog2 = 6;
inline constexpr int kTileSize = 1 << kTileLog2;  // 64
inline constexpr int kBlockLog2 = 2;
inline constexpr int kBlockSize = 1 << kBlockLog2;  // 4
inline constexpr int kBlockPixels = kBlockSize * kBlockSize;
inline constexpr int kBlocksPerTileSide = kTileSize / kBlockSize;
inline constexpr int kTilePixels = kTileSize * kTileSize;
inline constexpr int kColorChannels = 3;
inline constexpr int kColorPerBlock = kBlockPixels * kColorChannels;
inline constexpr int kSumsPerTile = kTilePixels * kColorChannels;

// The index of the 4×4 block holding tile-local pixel (lx, ly), in a tile's block-major layout.
constexpr size_t tileBlock(int lx, int ly) {
  return size_t(ly >> kBlockLog2) * kBlocksPerTileSide + size_t(lx >> kBlockLog2);
}

// Word w (0 or 1) of a pixel's sample mask (raster/coverage_masks.h) with all `samples` set.
constexpr uint32_t fullSampleWord(int samples, int w) {
  return w == 0 ? (samples >= 32 ? ~0u : (1u << samples) - 1) : (samples > 32 ? ~0u : 0u);
}

class FrameBuffer {
 public:
  // Allocates for a width × height raster (1 … 8192 each; checked) of `samples`
  // samples per pixel (1 … 64); with `sums`, colour sums besides (kSumsPerTile per tile).
  void resize(int width, int height, int samples = 1, bool sums = false);

  int width() const { return width_; }
  int height() const { return height_; }
  int samples() const { return samples_; }
  int tilesX() const { return tilesX_; }
  int tilesY() const { return tilesY_; }
  int tileCount() const { return tilesX_ * tilesY_; }

  float* tileDepth(int tile) { return depth_.get() + size_t(tile) * kTilePixels * samples_; }
  uint16_t* tileColor(int tile) {
    return color_.get() + size_t(tile) * kTilePixels * kColorChannels * samples_;
  }
  const float* tileDepth(int tile) const {
    return depth_.get() + size_t(tile) * kTilePixels * samples_;
  }
  const uint16_t* tileColor(int tile) const {
    return color_.get() + size_t(tile) * kTilePixels * kColorChannels * samples_;
  }
  // The tile's colour sums; nullptr unless allocated (resize with `sums`).
  int32_t* tileSums(int tile) {
    return sums_ ? sums_.get() + size_t(tile) * kSumsPerTile : nullptr;
  }

  // Offsets of sample s of pixel (x, y) inside its tile's depth and colour arrays, for a buffer of
  // `samples` samples per pixel.
  static size_t depthOffset(int x, int y, int samples = 1, int s = 0);
  static size_t colorOffset(int x, int y, int channel, int samples = 1, int s = 0);

 private:
  int width_ = 0, height_ = 0, samples_ = 1, tilesX_ = 0, tilesY_ = 0;
  size_t capacity_ = 0;  // pixels × samples allocated
  hwy::AlignedFreeUniquePtr<float[]> depth_;
  hwy::AlignedFreeUniquePtr<uint16_t[]> color_;
  size_t sumsCapacity_ = 0;  // tiles
  hwy::AlignedFreeUniquePtr<int32_t[]> sums_;
};

inline size_t FrameBuffer::depthOffset(int x, int y, int samples, int s) {
  int lx = x & (kTileSize - 1), ly = y & (kTileSize - 1);
  const size_t block = tileBlock(lx, ly);
  return (block * samples + size_t(s)) * kBlockPixels + (ly & (kBlockSize - 1)) * kBlockSize +
         (lx & (kBlockSize - 1));
}

inline size_t FrameBuffer::colorOffset(int x, int y, int channel, int samples, int s) {
  int lx = x & (kTileSize - 1), ly = y & (kTileSize - 1);
  const size_t block = tileBlock(lx, ly);
  return (block * samples + size_t(s)) * kColorPerBlock + channel * kBlockPixels +
         (ly & (kBlockSize - 1)) * kBlockSize + (lx & (kBlockSize - 1));
}

}  // namespace sv::raster
