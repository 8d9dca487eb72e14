// PNG through libpng's simplified API (no setjmp across C++ frames); PPM by hand.
#include <fmt/format.h>
#include <png.h>

#include <cstdio>
#include <memory>

#include "synthvis/image.h"

namespace sv {
namespace {

// The raster limit (8192², 192 MiB of RGB): a PNG header claiming more is refused before any
// allocation, so a tiny malicious file cannot ask for gigabytes.
constexpr int kMaxImageSide = 1 << 13;

bool endsWith(const std::string& s, const char* suffix) {
  const std::string x(suffix);
  if (s.size() < x.size()) return false;
  for (size_t i = 0; i < x.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(s[s.size() - x.size() + i])) != x[i]) return false;
  return true;
}

Status checkImage(const Image& image, const std::string& path) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != size_t(image.width) * image.height * 3)
    return Error{path, "", "image has inconsistent size"};
  return {};
}

}  // namespace

Status writeImage(const Image& image, const std::string& path) {
  if (endsWith(path, ".png")) return writePng(image, path);
  if (endsWith(path, ".ppm")) return writePpm(image, path);
  return Error{path, "", "unknown image format (use .png or .ppm)"};
}

Status writePng(const Image& image, const std::string& path) {
  if (Status s = checkImage(image, path); !s) return s;
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = PNG_FORMAT_RGB;
  // Declare the pixels sRGB-encoded so viewers show them as rendered.
  png.flags = 0;
  if (!png_image_write_to_file(&png, path.c_str(), 0, image.rgb.data(), image.width * 3, nullptr)) {
    std::string msg = png.message;
    png_image_free(&png);
    return Error{path, "", "cannot write PNG: " + msg};
  }
  return {};
}

Status writePpm(const Image& image, const std::string& path) {
  if (Status s = checkImage(image, path); !s) return s;
  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(path.c_str(), "wb"), &std::fclose);
  if (!f) return Error{path, "", "cannot open for writing"};
  const std::string header = fmt::format("P6\n{} {}\n255\n", image.width, image.height);
  if (std::fwrite(header.data(), 1, header.size(), f.get()) != header.size() ||
      std::fwrite(image.rgb.data(), 1, image.rgb.size(), f.get()) != image.rgb.size())
    return Error{path, "", "write failed"};
  return {};
}

namespace {

// Both readers: `png` has begun reading (from a file or from memory); `name` is for messages.
Result<Image> finishPngRead(png_image& png, const std::string& name) {
  if (png.width == 0 || png.height == 0 || png.width > kMaxImageSide ||
      png.height > kMaxImageSide) {
    png_image_free(&png);
    return Error{name, "", fmt::format("PNG size {}x{} is out of range", png.width, png.height)};
  }
  png.format = PNG_FORMAT_RGB;
  Image image;
  image.width = static_cast<int>(png.width);
  image.height = static_cast<int>(png.height);
  image.rgb.resize(PNG_IMAGE_SIZE(png));
  if (!png_image_finish_read(&png, nullptr, image.rgb.data(), 0, nullptr)) {
    std::string msg = png.message;
    png_image_free(&png);
    return Error{name, "", "cannot decode PNG: " + msg};
  }
  return image;
}

}  // namespace

Result<Image> readPng(const std::string& path) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str())) {
    std::string msg = png.message;
    png_image_free(&png);
    return Error{path, "", "cannot read PNG: " + msg};
  }
  return finishPngRead(png, path);
}

Result<Image> decodePng(const void* data, size_t size, const std::string& name) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&png, data, size)) {
    std::string msg = png.message;
    png_image_free(&png);
    return Error{name, "", "cannot read PNG: " + msg};
  }
  return finishPngRead(png, name);
}

}  // namespace sv
