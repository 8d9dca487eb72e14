#include "raster/framebuffer.h"

namespace sv::raster {

void FrameBuffer::resize(int width, int height, int samples) {
  const int tx = (width + kTileSize - 1) >> kTileLog2, ty = (height + kTileSize - 1) >> kTileLog2;
  const size_t needed = size_t(tx) * ty * kTilePixels * size_t(samples);
  if (needed > capacity_ || !depth_) {
    depth_ = hwy::AllocateAligned<float>(needed);
    color_ = hwy::AllocateAligned<uint16_t>(needed * kColorChannels);
    capacity_ = needed;
  }
  width_ = width;
  height_ = height;
  samples_ = samples;
  tilesX_ = tx;
  tilesY_ = ty;
}

}  // namespace sv::raster
