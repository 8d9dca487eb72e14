// Image files: PNG through the one PNG codec (texture/png.h); PPM by hand.
#include <fmt/format.h>

#include "synthvis/files.h"
#include "synthvis/image.h"
#include "texture/png.h"

namespace sv {
namespace {

constexpr int kMaxImageSide = 1 << 13;  // as the raster's

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
  return texture::writePng(path, image.width, image.height, 3, image.rgb.data());
}

Status writePpm(const Image& image, const std::string& path) {
  if (Status s = checkImage(image, path); !s) return s;
  const std::string header = fmt::format("P6\n{} {}\n255\n", image.width, image.height);
  return core::writeFile(path, {header, core::bytesOf(image.rgb.data(), image.rgb.size())});
}

namespace {

// The raster limit (8192², 192 MiB of RGB): a PNG header claiming more is refused before any
// allocation, so a tiny malicious file cannot ask for gigabytes.
constexpr texture::PngLimits kImageLimits{kMaxImageSide, int64_t(kMaxImageSide) * kMaxImageSide};

Result<Image> toImage(Result<texture::PngPixels> png) {
  if (!png.ok()) return png.error();
  Image image;
  image.width = png.value().width;
  image.height = png.value().height;
  image.rgb = std::move(png.value().data);
  return image;
}

}  // namespace

Result<Image> readPng(const std::string& path) {
  return toImage(texture::readPng(path, texture::PngLayout::rgb8, kImageLimits));
}

Result<Image> decodePng(const void* data, size_t size, const std::string& name) {
  return toImage(texture::decodePng(data, size, name, texture::PngLayout::rgb8, kImageLimits));
}

}  // namespace sv
