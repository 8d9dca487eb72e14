// Based on: SPEC §11 (height tables); issue 29 (16-bit PNG height maps): a grey PNG's codes as a
// table, placed and scaled as the caller says (a PNG holds no georeferencing).
#include <fmt/format.h>

#include <cmath>
#include <optional>

#include "formats/heights.h"
#include "texture/png.h"

namespace sv::formats {
using detail::checkPlacement;
using detail::finite;
namespace {

// The caller's height scale and offset, checked before the file is read: an error in them is the
// caller's, whatever the file holds.
std::optional<Error> checkHeightScale(const PngPlacement& placement, const std::string& name) {
  if (!finite({placement.offset, placement.scale}) || !(placement.scale > 0))
    return Error{name, "",
                 fmt::format("PNG height scale {} and offset {} are not a positive scale and a "
                             "finite offset",
                             placement.scale, placement.offset)};
  return std::nullopt;
}

texture::PngLimits pngLimits(int64_t maxSamples) {
  texture::PngLimits limits;
  limits.maxSide = kMaxHeightSide;
  limits.maxPixels = std::min(kMaxHeightSamples, maxSamples);
  return limits;
}

// A decoded grey PNG as a height table: its codes unchanged, offset + scale·code metres, placed
// where the caller says.
Result<HeightField> placePng(Result<texture::PngGrey> png, const std::string& name,
                             const PngPlacement& placement) {
  if (!png.ok()) return png.error();
  if (png->width < 2 || png->height < 2)
    return Error{name, "",
                 fmt::format("a height table needs at least 2 × 2 samples, not {} × {}", png->width,
                             png->height)};
  HeightField f;
  f.width = png->width;
  f.height = png->height;
  f.originU = placement.originU;
  f.originV = placement.originV;
  f.spacingU = placement.spacingU;
  f.spacingV = placement.spacingV;
  if (std::optional<Error> e = checkPlacement(f, name)) return *e;
  // The same bound as quantize's, on the heights the codes can stand for.
  const double top = placement.offset + placement.scale * ((1 << png->bitDepth) - 1);
  if (std::fabs(placement.offset) > 1e7 || std::fabs(top) > 1e7)
    return Error{name, "",
                 fmt::format("heights from {} to {} are beyond ±10 000 km", placement.offset, top)};
  f.offset = placement.offset;
  f.scale = placement.scale;
  f.q = std::move(png->samples);
  f.source = name;
  return f;
}

}  // namespace

Result<HeightField> decodePng16(const void* data, size_t size, const std::string& name,
                                const PngPlacement& placement, int64_t maxSamples) {
  if (std::optional<Error> e = checkHeightScale(placement, name)) return *e;
  return placePng(texture::decodePngGrey(data, size, name, pngLimits(maxSamples)), name, placement);
}

Result<HeightField> loadPng16(const std::string& path, const PngPlacement& placement) {
  if (std::optional<Error> e = checkHeightScale(placement, path)) return *e;
  return placePng(texture::readPngGrey(path, pngLimits(kMaxHeightSamples)), path, placement);
}

}  // namespace sv::formats
