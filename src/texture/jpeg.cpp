// JPEG decoding through TurboJPEG (texture/jpeg.h).
#include "texture/jpeg.h"

#include <fmt/format.h>
#include <turbojpeg.h>

#include <cstring>
#include <memory>

namespace sv::texture {

bool looksLikeJpeg(const void* data, size_t size) {
  const auto* b = static_cast<const unsigned char*>(data);
  return size >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF;
}

Result<JpegPixels> decodeJpeg(const void* data, size_t size, const std::string& name, int maxSide,
                              int64_t maxPixels) {
  if (!looksLikeJpeg(data, size)) return Error{name, "", "not a JPEG file"};
  if (size > (size_t(1) << 31)) return Error{name, "", "JPEG file too large"};
  std::unique_ptr<void, int (*)(tjhandle)> tj(tjInitDecompress(), &tjDestroy);
  if (!tj) return Error{name, "", "cannot start the JPEG decoder"};
  auto* bytes = static_cast<const unsigned char*>(data);
  int width = 0, height = 0, subsampling = 0, colorspace = 0;
  if (tjDecompressHeader3(tj.get(), bytes, static_cast<unsigned long>(size), &width, &height,
                          &subsampling, &colorspace) != 0)
    return Error{name, "", fmt::format("invalid JPEG: {}", tjGetErrorStr2(tj.get()))};
  if (width < 1 || height < 1) return Error{name, "", "invalid JPEG: no image in it"};
  if (width > maxSide || height > maxSide ||
      int64_t(width) * height > maxPixels)
    return Error{name, "",
                 fmt::format("JPEG of {}x{} pixels exceeds the limits ({} a side, {} pixels)",
                             width, height, maxSide, maxPixels)};
  // Baseline JPEG compresses at most about 1:1000 even for a flat image; a file much shorter than
  // its header's size claims is refused before the pixels are allocated.
  if (int64_t(width) * height > int64_t(size) * 4096)
    return Error{name, "", fmt::format("JPEG of {}x{} pixels in only {} bytes: truncated or "
                                       "hostile", width, height, size)};
  JpegPixels out;
  out.width = width;
  out.height = height;
  out.rgba.resize(size_t(width) * size_t(height) * 4);
  // Warnings (a corrupt but decodable stream) are accepted; errors are not.
  if (tjDecompress2(tj.get(), bytes, static_cast<unsigned long>(size), out.rgba.data(), width, 0,
                    height, TJPF_RGBA, TJFLAG_ACCURATEDCT) != 0 &&
      tjGetErrorCode(tj.get()) == TJERR_FATAL)
    return Error{name, "", fmt::format("invalid JPEG: {}", tjGetErrorStr2(tj.get()))};
  return out;
}

}  // namespace sv::texture
