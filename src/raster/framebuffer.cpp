#include "raster/framebuffer.h"

namespace sv::raster {

void FrameBuffer::resize(int width, int height, int samples, bool sums) {
  const int tx = (width + kTileSize - 1) >> kTileLog2, ty = (height + kTileSize - 1) >> kTileLog2;
  const size_t needed = size_t(tx) * ty * kTilePixels * size_t(samples);
  if (needed > capacity_ || !depth_) {
    depth_ = hwy::AllocateAligned<float>(needed);
    color_ = hwy::AllocateAligned<uint16_t>(needed * kColorChannels);
    capacity_ = needed;
  }
  const size_t tiles = size_t(tx) * ty;
  if (sums && tiles > sumsCapacity_) {
    sums_ = hwy::AllocateAligned<int32_t>(tiles * kSumsPerTile);
    sumsCapacity_ = tiles;
  }
  width_ = width;
  height_ = height;
  samples_ = samples;
  tilesX_ = tx;
  tilesY_ = ty;
}

}  // namespace sv::raster
