// PNG files (libpng's simplified API, no setjmp across C++ frames): the one reader and writer of
// synthvis — texture maps (texture.h) and the images the display stage writes and `compare` reads
// (synthvis/image.h) both go through here.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "synthvis/result.h"

namespace sv::texture {

// How a PNG's samples are read: 8-bit RGB (alpha dropped); or as the file holds them — 8-bit
// sRGB-encoded RGBA for 8-bit files, 16-bit linear RGBA with alpha premultiplied (libpng's linear
// form) for 16-bit ones.
enum class PngLayout : uint8_t { rgb8, rgba8OrLinear16 };

// What a header may claim before anything is allocated: at most maxSide a side and maxPixels in
// all. A file is also refused when it is too short for the size its header states (deflate
// expands at most about 1032:1), so a 60-byte file cannot cost half a gigabyte — when its size can
// be known (a pipe's cannot).
struct PngLimits {
  int maxSide = 1 << 13;
  int64_t maxPixels = int64_t(1) << 26;
};

struct PngPixels {
  int width = 0, height = 0;
  bool linear16 = false;      // rgba8OrLinear16 of a 16-bit file: `data` holds uint16 samples
  std::vector<uint8_t> data;  // rows, top first: 3 or 4 bytes a pixel, or 4 uint16
};

// The PNG at `path`, or `size` bytes at `data` (`name` names them in errors). Errors name the file
// and the problem.
Result<PngPixels> readPng(const std::string& path, PngLayout layout, const PngLimits& limits);
Result<PngPixels> decodePng(const void* data, size_t size, const std::string& name,
                            PngLayout layout, const PngLimits& limits);

// A greyscale PNG's samples exactly as the file stores them, for data that is not light (height
// maps, terrain/load_heights.cpp): 8- or 16-bit grey only (colour, alpha, palettes and 1/2/4-bit
// grey are refused), and no gamma or colour space applied — the gAMA, sRGB, iCCP, cHRM and tRNS
// chunks are ignored, so a code comes out as the number the file holds whatever tool wrote it.
struct PngGrey {
  int width = 0, height = 0;
  int bitDepth = 0;               // 8 or 16: codes 0…255 or 0…65535
  std::vector<uint16_t> samples;  // width × height, rows top first
};
Result<PngGrey> readPngGrey(const std::string& path, const PngLimits& limits);
Result<PngGrey> decodePngGrey(const void* data, size_t size, const std::string& name,
                              const PngLimits& limits);

// `width` × `height` pixels of 8-bit RGB (channels 3) or RGBA (4), rows top first, as a PNG file
// at `path`, or as PNG bytes in memory.
Status writePng(const std::string& path, int width, int height, int channels, const uint8_t* rows);
Result<std::vector<uint8_t>> encodePng(const std::string& name, int width, int height, int channels,
                                       const uint8_t* rows);
// `width` × `height` 16-bit grey samples, rows top first, as a 16-bit greyscale PNG (tagged gamma
// 1.0; readPngGrey gives the same codes back).
Status writePngGrey16(const std::string& path, int width, int height, const uint16_t* samples);
Result<std::vector<uint8_t>> encodePngGrey16(const std::string& name, int width, int height,
                                             const uint16_t* samples);
// The same with 8-bit samples (an 8-bit greyscale PNG; readPngGrey gives the same codes back: it
// ignores the sRGB chunk libpng writes).
Result<std::vector<uint8_t>> encodePngGrey8(const std::string& name, int width, int height,
                                            const uint8_t* samples);

}  // namespace sv::texture
