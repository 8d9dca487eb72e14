#include "texture/png.h"

#include <fmt/format.h>
#include <png.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>

namespace sv::texture {
namespace {

constexpr uint64_t kUnknownSize = ~uint64_t(0);

// The size `png`'s header states (begin_read has run), against `limits` and against what `bytes`
// of file can hold; on failure `png` is freed.
std::optional<Error> checkSize(png_image& png, uint64_t bytes, const std::string& name,
                               const PngLimits& limits) {
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
  return std::nullopt;
}

// libpng has begun reading `png` (`bytes` long); finish as `layout` says, within `limits`.
Result<PngPixels> finishRead(png_image& png, uint64_t bytes, const std::string& name,
                             PngLayout layout, const PngLimits& limits) {
  if (std::optional<Error> e = checkSize(png, bytes, name, limits)) return *e;
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

uint32_t bigEndian32(const uint8_t* p) {
  return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | uint32_t(p[3]);
}

// The PNG `bytes` without the chunks that make libpng's simplified API change samples (it applies
// gAMA, sRGB, iCCP and cHRM to reach its output gamma, and composes tRNS's transparent grey onto a
// background); without them a 16-bit file is taken as linear and an 8-bit one as sRGB, and each
// is read unchanged into the output of its own kind. Also the IHDR's bit depth and colour type
// (0, 0 when there is no readable IHDR). Anything malformed is copied as it is, for libpng to
// report.
std::vector<uint8_t> withoutColourChunks(const uint8_t* bytes, size_t size, int* bitDepth,
                                         int* colourType) {
  *bitDepth = *colourType = 0;
  constexpr size_t kSignature = 8;
  if (size < kSignature) return std::vector<uint8_t>(bytes, bytes + size);
  std::vector<uint8_t> out(bytes, bytes + kSignature);
  out.reserve(size);
  size_t at = kSignature;
  while (size - at >= 12) {  // length, type, CRC
    const uint64_t length = bigEndian32(bytes + at);
    if (length > size - at - 12) break;
    const size_t chunk = size_t(length) + 12;
    const uint8_t* type = bytes + at + 4;
    if (std::memcmp(type, "IHDR", 4) == 0 && length >= 13 && at == kSignature) {
      *bitDepth = bytes[at + 8 + 8];
      *colourType = bytes[at + 8 + 9];
    }
    constexpr std::array<const char*, 5> kDropped = {"gAMA", "sRGB", "iCCP", "cHRM", "tRNS"};
    bool dropped = false;
    for (const char* d : kDropped) dropped = dropped || std::memcmp(type, d, 4) == 0;
    if (!dropped) out.insert(out.end(), bytes + at, bytes + at + chunk);
    at += chunk;
  }
  out.insert(out.end(), bytes + at, bytes + size);
  return out;
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

Result<PngGrey> decodePngGrey(const void* data, size_t size, const std::string& name,
                              const PngLimits& limits) {
  int bitDepth = 0, colourType = 0;
  const std::vector<uint8_t> bytes =
      withoutColourChunks(static_cast<const uint8_t*>(data), size, &bitDepth, &colourType);
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&png, bytes.data(), bytes.size()))
    return beginFailed(png, name);
  // Colour type 0 is grey without alpha (PNG spec §11.2.2).
  if (colourType != 0 || (bitDepth != 8 && bitDepth != 16)) {
    png_image_free(&png);
    return Error{name, "",
                 fmt::format("PNG of colour type {} and bit depth {} is not 8- or 16-bit greyscale",
                             colourType, bitDepth)};
  }
  if (std::optional<Error> e = checkSize(png, size, name, limits)) return *e;
  PngGrey out;
  out.width = int(png.width);
  out.height = int(png.height);
  out.bitDepth = bitDepth;
  out.samples.resize(size_t(png.width) * png.height);
  std::vector<uint8_t> narrow;
  void* buffer = out.samples.data();
  if (bitDepth == 16) {
    png.format = PNG_FORMAT_LINEAR_Y;
  } else {
    png.format = PNG_FORMAT_GRAY;
    narrow.resize(out.samples.size());
    buffer = narrow.data();
  }
  if (!png_image_finish_read(&png, nullptr, buffer, 0, nullptr)) {
    const std::string message = png.message;
    png_image_free(&png);
    return Error{name, "", "cannot decode PNG: " + message};
  }
  if (bitDepth == 8) std::copy(narrow.begin(), narrow.end(), out.samples.begin());
  return out;
}

Result<PngGrey> readPngGrey(const std::string& path, const PngLimits& limits) {
  // The whole file first (its colour chunks are dropped before libpng sees it), no larger than
  // the largest image the limits allow could take at no compression.
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error))
    return Error{path, "", error ? "cannot open PNG file: " + error.message() : "not a file"};
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error{path, "", "cannot open PNG file"};
  const uintmax_t bytes = std::filesystem::file_size(path, error);
  const uint64_t largest = uint64_t(limits.maxPixels) * 2 * 1001 / 1000 + (uint64_t(1) << 20);
  if (error || bytes > largest)
    return Error{path, "", error ? "cannot tell the PNG file's size" : "PNG file is too large"};
  std::vector<char> data(bytes);
  if (!in.read(data.data(), std::streamsize(bytes))) return Error{path, "", "cannot read PNG file"};
  return decodePngGrey(data.data(), data.size(), path, limits);
}

Status writePngGrey16(const std::string& path, int width, int height, const uint16_t* samples) {
  png_image png = header(width, height, 1);
  png.format = PNG_FORMAT_LINEAR_Y;
  if (!png_image_write_to_file(&png, path.c_str(), 0, samples, 0, nullptr))
    return writeFailed(png, path, "cannot write PNG");
  return {};
}

namespace {
// One greyscale image (the format set in `png`) to PNG bytes in memory.
Result<std::vector<uint8_t>> encodeGrey(png_image& png, const std::string& name,
                                        const void* samples) {
  png_alloc_size_t bytes = 0;
  if (!png_image_write_to_memory(&png, nullptr, &bytes, 0, samples, 0, nullptr))
    return writeFailed(png, name, "cannot encode PNG");
  std::vector<uint8_t> out(bytes);
  if (!png_image_write_to_memory(&png, out.data(), &bytes, 0, samples, 0, nullptr))
    return writeFailed(png, name, "cannot encode PNG");
  out.resize(bytes);
  return out;
}
}  // namespace

Result<std::vector<uint8_t>> encodePngGrey16(const std::string& name, int width, int height,
                                             const uint16_t* samples) {
  png_image png = header(width, height, 1);
  png.format = PNG_FORMAT_LINEAR_Y;
  return encodeGrey(png, name, samples);
}

Result<std::vector<uint8_t>> encodePngGrey8(const std::string& name, int width, int height,
                                            const uint8_t* samples) {
  png_image png = header(width, height, 1);
  png.format = PNG_FORMAT_GRAY;
  return encodeGrey(png, name, samples);
}

}  // namespace sv::texture
