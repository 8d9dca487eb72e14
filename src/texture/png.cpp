#include "texture/png.h"

#include <fmt/format.h>
#include <png.h>

#include <filesystem>

namespace sv::texture {
namespace {

constexpr uint64_t kUnknownSize = ~uint64_t(0);

// libpng has begun reading `png` (`bytes` long); finish as `layout` says, within `limits`.
Result<PngPixels> finishRead(png_image& png, uint64_t bytes, const std::string& name,
                             PngLayout layout, const PngLimits& limits) {
  if (png.width == 0 || png.height == 0 || png.width > uint32_t(limits.maxSide) ||
      png.height > uint32_t(limits.maxSide) ||
      int64_t(png.width) * int64_t(png.height) > limits.maxPixels) {
    png_image_free(&png);
    return Error{name, "",
                 fmt::format("PNG size {}x{} is out of range (sides 1…{}, at most {} pixels)",
                             png.width, png.height, limits.maxSide, limits.maxPixels)};
  }
  // The file's own samples (the format begin_read found) against what its bytes can hold; a size
  // that cannot be known (a pipe) bounds nothing.
  if (bytes != kUnknownSize && uint64_t(PNG_IMAGE_SIZE(png)) > bytes * 1032 + 65536) {
    png_image_free(&png);
    return Error{name, "",
                 fmt::format("{} bytes of PNG cannot hold the {}x{} image its header states", bytes,
                             png.width, png.height)};
  }
  PngPixels out;
  out.width = int(png.width);
  out.height = int(png.height);
  out.linear16 = layout == PngLayout::rgba8OrLinear16 && (png.format & PNG_FORMAT_FLAG_LINEAR);
  png.format = layout == PngLayout::rgb8 ? PNG_FORMAT_RGB
               : out.linear16            ? PNG_FORMAT_LINEAR_RGB_ALPHA
                                         : PNG_FORMAT_RGBA;
  out.data.resize(PNG_IMAGE_SIZE(png));
  if (!png_image_finish_read(&png, nullptr, out.data.data(), 0, nullptr)) {
    const std::string message = png.message;
    png_image_free(&png);
    return Error{name, "", "cannot decode PNG: " + message};
  }
  return out;
}

Error beginFailed(png_image& png, const std::string& name) {
  const std::string message = png.message;
  png_image_free(&png);
  return Error{name, "", "cannot read PNG: " + message};
}

png_image header(int width, int height, int channels) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = png_uint_32(width);
  png.height = png_uint_32(height);
  png.format = channels == 4 ? PNG_FORMAT_RGBA : PNG_FORMAT_RGB;
  return png;
}

Error writeFailed(png_image& png, const std::string& name, const char* what) {
  const std::string message = png.message;
  png_image_free(&png);
  return Error{name, "", fmt::format("{}: {}", what, message)};
}

}  // namespace

Result<PngPixels> readPng(const std::string& path, PngLayout layout, const PngLimits& limits) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str())) return beginFailed(png, path);
  std::error_code error;
  const uintmax_t bytes = std::filesystem::file_size(path, error);
  return finishRead(png, error ? kUnknownSize : uint64_t(bytes), path, layout, limits);
}

Result<PngPixels> decodePng(const void* data, size_t size, const std::string& name,
                            PngLayout layout, const PngLimits& limits) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&png, data, size)) return beginFailed(png, name);
  return finishRead(png, size, name, layout, limits);
}

Status writePng(const std::string& path, int width, int height, int channels, const uint8_t* rows) {
  png_image png = header(width, height, channels);
  if (!png_image_write_to_file(&png, path.c_str(), 0, rows, width * channels, nullptr))
    return writeFailed(png, path, "cannot write PNG");
  return {};
}

Result<std::vector<uint8_t>> encodePng(const std::string& name, int width, int height, int channels,
                                       const uint8_t* rows) {
  png_image png = header(width, height, channels);
  // First the size, then the bytes (libpng's two-call protocol for memory output).
  png_alloc_size_t bytes = 0;
  if (!png_image_write_to_memory(&png, nullptr, &bytes, 0, rows, 0, nullptr))
    return writeFailed(png, name, "cannot encode PNG");
  std::vector<uint8_t> out(bytes);
  if (!png_image_write_to_memory(&png, out.data(), &bytes, 0, rows, 0, nullptr))
    return writeFailed(png, name, "cannot encode PNG");
  out.resize(bytes);
  return out;
}

}  // namespace sv::texture
