// SGI image files (.rgb, .rgba, .int, .inta, .bw, .sgi): the texture format of OpenFlight
// databases (texture.h's readTextureImage recognises them by their magic number).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "synthvis/result.h"

namespace sv::texture {

// `size` bytes at `data` (`name` names them in errors) as 8-bit RGBA rows, top first: grey
// repeated into r, g, b; alpha 255 without an alpha channel; 16-bit channels keep their high
// byte. Verbatim and run-length encoded files, 1 to 4 channels. The header's size is checked
// against `maxSide` and `maxPixels` before anything is allocated; every run stays inside the file
// and its row.
struct SgiPixels {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;
};
Result<SgiPixels> decodeSgi(const void* data, size_t size, const std::string& name, int maxSide,
                            int64_t maxPixels);

// Whether `size` bytes at `data` begin as an SGI image does (magic 474, big-endian).
bool looksLikeSgi(const void* data, size_t size);

}  // namespace sv::texture
