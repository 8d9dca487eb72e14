#include "raster/framebuffer.h"

namespace sv::raster {

void FrameBuffer::resize(int width, int height) {
  int tx = (width + kTileSize - 1) >> kTileLog2, ty = (height + kTileSize - 1) >> kTileLog2;
  if (tx * ty != tilesX_ * tilesY_ || !depth_) {
    depth_ = hwy::AllocateAligned<float>(size_t(tx) * ty * kTilePixels);
    color_ = hwy::AllocateAligned<uint16_t>(size_t(tx) * ty * kTilePixels * kColorChannels);
  }
  width_ = width;
  height_ = height;
  tilesX_ = tx;
  tilesY_ = ty;
}

}  // namespace sv::raster
