// JPEG files (libjpeg-turbo's TurboJPEG API: errors as return values, no setjmp across C++
// frames): texture maps in glTF files and OBJ materials (texture.h's readTextureImage).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "synthvis/result.h"

namespace sv::texture {

// `size` bytes at `data` (`name` names them in errors) as 8-bit sRGB-encoded RGBA rows, top first
// (alpha 255; greyscale and CMYK files converted). The header's size is checked against
// `maxSide` and `maxPixels` before anything is allocated.
struct JpegPixels {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;
};
Result<JpegPixels> decodeJpeg(const void* data, size_t size, const std::string& name, int maxSide,
                              int64_t maxPixels);

// Whether `size` bytes at `data` begin as a JPEG file does (SOI marker FF D8 FF).
bool looksLikeJpeg(const void* data, size_t size);

}  // namespace sv::texture
