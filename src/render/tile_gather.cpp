// Based on: SPEC §3.4 (seed 000: one picture over a matrix of processors, each a sparse raster),
// issue 36 (the parts' tiles gathered to one, MPI_Gatherv's pattern).
#include "render/tile_gather.h"

#include <algorithm>
#include <cstring>

#include "core/timing.h"

namespace sv::render {
namespace {

// Calls f(row pointer, row bytes) for every row of every tile of `part`, in the packing order.
template <class F>
void forShareRows(const SharedPixels& image, const TileShare& share, int part, F&& f) {
  const int side = image.tileSide;
  const int tilesX = (image.width + side - 1) / side, tilesY = (image.height + side - 1) / side;
  const TileShare as{share.parts, part, nullptr};
  const size_t stride = size_t(image.width) * size_t(image.pixelBytes);
  for (int ty = 0; ty < tilesY; ++ty)
    for (int tx = 0; tx < tilesX; ++tx) {
      if (!as.owns(tx, ty)) continue;
      const int x0 = tx * side, y0 = ty * side;
      const size_t rowBytes = size_t(std::min(side, image.width - x0)) * size_t(image.pixelBytes);
      for (int y = y0; y < std::min(y0 + side, image.height); ++y)
        f(image.pixels + size_t(y) * stride + size_t(x0) * size_t(image.pixelBytes), rowBytes);
    }
}

}  // namespace

size_t sharedBytes(const SharedPixels& image, const TileShare& share, int part) {
  size_t n = 0;
  forShareRows(image, share, part, [&](const uint8_t*, size_t bytes) { n += bytes; });
  return n;
}

void packShare(const SharedPixels& image, const TileShare& share, int part,
               std::vector<uint8_t>& out) {
  out.resize(sharedBytes(image, share, part));
  size_t at = 0;
  forShareRows(image, share, part, [&](const uint8_t* row, size_t bytes) {
    std::memcpy(out.data() + at, row, bytes);
    at += bytes;
  });
}

void unpackShare(const SharedPixels& image, const TileShare& share, int part,
                 const std::vector<uint8_t>& in) {
  size_t at = 0;
  forShareRows(image, share, part, [&](uint8_t* row, size_t bytes) {
    std::memcpy(row, in.data() + at, bytes);
    at += bytes;
  });
}

Status gatherShare(const SharedPixels& image, const TileShare& share, ShareBuffers& b,
                   FrameStats& stats) {
  const auto t0 = core::Clock::now();
  if (share.part != 0) {
    packShare(image, share, share.part, b.mine);
    if (Status s = share.exchange->gather(b.mine, b.all); !s) return s;
    stats.shareBytes += b.mine.size();
  } else {
    // Part 0's own tiles are in place already.
    b.mine.clear();
    b.all.resize(size_t(share.parts));
    for (int p = 1; p < share.parts; ++p) b.all[size_t(p)].resize(sharedBytes(image, share, p));
    if (Status s = share.exchange->gather(b.mine, b.all); !s) return s;
    for (int p = 1; p < share.parts; ++p) {
      unpackShare(image, share, p, b.all[size_t(p)]);
      stats.shareBytes += b.all[size_t(p)].size();
    }
  }
  stats.shareMs += core::msSince(t0);
  return {};
}

}  // namespace sv::render
