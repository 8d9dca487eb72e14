// 8-bit RGB images, and the files synthvis reads and writes (PNG, binary PPM).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "synthvis/result.h"

namespace sv {

// A display-ready image: 8-bit sRGB-encoded (or display-gamma) RGB, rows top to bottom.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgb;  // width·height·3

  const uint8_t* pixel(int x, int y) const { return &rgb[(size_t(y) * width + x) * 3]; }
  uint8_t* pixel(int x, int y) { return &rgb[(size_t(y) * width + x) * 3]; }
};

// The display channels of one frame side by side (SPEC §9), left to right in the given order, in
// one image as wide as their widths summed and as high as the highest; a shorter image sits at the
// top, the rows below it black. No images: an empty image.
Image mosaic(const std::vector<Image>& images);

// Writes by extension: .png (8-bit RGB) or .ppm (binary P6). Errors name the file.
Status writeImage(const Image& image, const std::string& path);
Status writePng(const Image& image, const std::string& path);
Status writePpm(const Image& image, const std::string& path);
// Reads an 8-bit or 16-bit PNG of any colour type into 8-bit RGB (alpha dropped).
Result<Image> readPng(const std::string& path);
// The same from bytes in memory; `name` is used in error messages.
Result<Image> decodePng(const void* data, size_t size, const std::string& name);

}  // namespace sv
