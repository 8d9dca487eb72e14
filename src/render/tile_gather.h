// A shared channel's image assembled on part 0 (issue 36, synthvis/tile_share.h): every part's
// finished pixels, tile by tile, gathered through the share's exchange.
#pragma once

#include <cstdint>
#include <vector>

#include "synthvis/frame_stats.h"
#include "synthvis/result.h"
#include "synthvis/tile_share.h"

namespace sv::render {

// An image's pixels as rows of `width` × `pixelBytes` bytes (an Image's 8-bit RGB, or the tent
// filter's linear 16-bit RGB), and the side of a raster tile in its pixels (64 / supersampling).
struct SharedPixels {
  uint8_t* pixels = nullptr;
  int width = 0, height = 0;
  int pixelBytes = 3;
  int tileSide = 64;
};

// Part `part`'s pixels, its tiles in raster order, each tile's rows top to bottom (clipped to the
// image): what it sends part 0. Its size first.
size_t sharedBytes(const SharedPixels& image, const TileShare& share, int part);
void packShare(const SharedPixels& image, const TileShare& share, int part,
               std::vector<uint8_t>& out);
void unpackShare(const SharedPixels& image, const TileShare& share, int part,
                 const std::vector<uint8_t>& in);

// What gatherShare keeps from frame to frame: fresh buffers of megabytes cost their page faults
// every frame (a 1080p half frame's three took a millisecond).
struct ShareBuffers {
  std::vector<uint8_t> mine;
  std::vector<std::vector<uint8_t>> all;
};

// Every part's tiles into part 0's image (the others' images keep their own tiles alone); the
// bytes and time go to stats.shareBytes, shareMs.
Status gatherShare(const SharedPixels& image, const TileShare& share, ShareBuffers& buffers,
                   FrameStats& stats);

}  // namespace sv::render
