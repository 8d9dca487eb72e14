#include "raster/framebuffer.h"

#include "core/check.h"

namespace sv::raster {

void FrameBuffer::resize(int width, int height, int samples, bool sums) {
  SV_CHECK(width >= 1 && width <= 8192 && height >= 1 && height <= 8192);
  SV_CHECK(samples >= 1 && samples <= 64);
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
