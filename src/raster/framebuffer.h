// The frame buffer the rasterizer writes: depth and linear colour, stored tile by tile.
//
// Layout. The raster is cut into 64×64-pixel tiles (the level-6 windows of the quadtree over the
// enclosing 2^n square, SPEC §2 "non-power-of-two rasters"); tiles that stick out of the raster are
// stored whole and cropped on output. Inside a tile, 4×4-pixel blocks are stored one after the
// other in row-major block order, and inside a block the 16 pixels in row-major order — so a block,
// the rasterizer's leaf, is one contiguous run of 16 values, one or a few SIMD vectors.
// Colour is planar per block (16 R, 16 G, 16 B, as uint16 linear light 0…65535), so the kernels never
// interleave; output applies gamma through look-up tables (SPEC §8).
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

class FrameBuffer {
 public:
  // Allocates for a width × height raster (1 … 8192 each; checked by the caller).
  void resize(int width, int height);

  int width() const { return width_; }
  int height() const { return height_; }
  int tilesX() const { return tilesX_; }
  int tilesY() const { return tilesY_; }
  int tileCount() const { return tilesX_ * tilesY_; }

  float* tileDepth(int tile) { return depth_.get() + size_t(tile) * kTilePixels; }
  uint16_t* tileColor(int tile) { return color_.get() + size_t(tile) * kTilePixels * kColorChannels; }
  const float* tileDepth(int tile) const { return depth_.get() + size_t(tile) * kTilePixels; }
  const uint16_t* tileColor(int tile) const {
    return color_.get() + size_t(tile) * kTilePixels * kColorChannels;
  }

  // Offsets of pixel (x, y) inside its tile's depth and colour arrays.
  static size_t depthOffset(int x, int y);
  static size_t colorOffset(int x, int y, int channel);

 private:
  int width_ = 0, height_ = 0, tilesX_ = 0, tilesY_ = 0;
  hwy::AlignedFreeUniquePtr<float[]> depth_;
  hwy::AlignedFreeUniquePtr<uint16_t[]> color_;
};

inline size_t FrameBuffer::depthOffset(int x, int y) {
  int lx = x & (kTileSize - 1), ly = y & (kTileSize - 1);
  int block = (ly >> kBlockLog2) * kBlocksPerTileSide + (lx >> kBlockLog2);
  return size_t(block) * kBlockPixels + (ly & (kBlockSize - 1)) * kBlockSize + (lx & (kBlockSize - 1));
}

inline size_t FrameBuffer::colorOffset(int x, int y, int channel) {
  int lx = x & (kTileSize - 1), ly = y & (kTileSize - 1);
  int block = (ly >> kBlockLog2) * kBlocksPerTileSide + (lx >> kBlockLog2);
  return size_t(block) * kColorPerBlock + channel * kBlockPixels +
         (ly & (kBlockSize - 1)) * kBlockSize + (lx & (kBlockSize - 1));
}

}  // namespace sv::raster
