// Based on: Paul Haeberli, "The SGI Image File Format", version 1.00 (Silicon Graphics, 1992) —
// the 512-byte big-endian header (magic 474, storage, bytes per channel, dimension, sizes), the
// planar channels with rows bottom first, and the run-length encoding with its offset and length
// tables.
#include "texture/sgi.h"

#include <fmt/format.h>

#include <algorithm>

namespace sv::texture {
namespace {

constexpr size_t kHeaderBytes = 512;

uint32_t be(const uint8_t* p, int n) {
  uint32_t v = 0;
  for (int i = 0; i < n; ++i) v = v << 8 | p[i];
  return v;
}

}  // namespace

bool looksLikeSgi(const void* data, size_t size) {
  const auto* p = static_cast<const uint8_t*>(data);
  return size >= 2 && p[0] == 0x01 && p[1] == 0xDA;
}

Result<SgiPixels> decodeSgi(const void* data, size_t size, const std::string& name, int maxSide,
                            int64_t maxPixels) {
  const auto* p = static_cast<const uint8_t*>(data);
  auto fail = [&](const std::string& why) { return Error{name, "", "SGI image: " + why}; };
  if (size < kHeaderBytes || !looksLikeSgi(data, size)) return fail("shorter than its header");
  const int storage = p[2], bpc = p[3];
  const uint32_t dimension = be(p + 4, 2);
  const int width = int(be(p + 6, 2));
  const int height = dimension >= 2 ? int(be(p + 8, 2)) : 1;
  const int channels = dimension >= 3 ? int(be(p + 10, 2)) : 1;
  if (storage > 1) return fail(fmt::format("unknown storage {}", storage));
  if (bpc != 1 && bpc != 2) return fail(fmt::format("{} bytes a channel (1 or 2)", bpc));
  if (dimension < 1 || dimension > 3) return fail(fmt::format("dimension {}", dimension));
  if (channels < 1 || channels > 4) return fail(fmt::format("{} channels (1 to 4)", channels));
  if (be(p + 104, 4) != 0) return fail("colour-mapped images are not supported");
  if (width < 1 || height < 1 || width > maxSide || height > maxSide ||
      int64_t(width) * height > maxPixels)
    return fail(fmt::format("size {}×{} (1 to {} a side, {} pixels)", width, height, maxSide,
                            maxPixels));
  const size_t rows = size_t(height) * size_t(channels);
  // The channel planes' samples, 8 bits each, row r of channel c at (c·height + r)·width.
  std::vector<uint8_t> plane(rows * size_t(width));
  if (storage == 0) {
    if ((size - kHeaderBytes) / size_t(bpc) < plane.size()) return fail("truncated");
    for (size_t i = 0; i < plane.size(); ++i) plane[i] = p[kHeaderBytes + i * size_t(bpc)];
  } else {
    if ((size - kHeaderBytes) / 8 < rows) return fail("truncated run tables");
    const uint8_t* starts = p + kHeaderBytes;
    const uint8_t* lengths = starts + 4 * rows;
    for (size_t row = 0; row < rows; ++row) {
      const size_t start = be(starts + 4 * row, 4), length = be(lengths + 4 * row, 4);
      if (start > size || length > size - start)
        return fail(fmt::format("run {} lies outside the file", row));
      uint8_t* out = &plane[row * size_t(width)];
      size_t at = start, x = 0;
      const size_t end = start + length;
      // Each unit (a byte, or a 16-bit word): count in its low 7 bits; with the high bit, that
      // many literal units follow, else one unit repeated; count 0 ends the row. A unit's value
      // is its first byte (a 16-bit one's high byte).
      auto unit = [&](size_t i) { return p[i]; };
      while (at + size_t(bpc) <= end) {
        const uint32_t head = be(p + at, bpc);
        at += size_t(bpc);
        const size_t count = head & 0x7F;
        if (count == 0) break;
        if (count > size_t(width) - x) return fail(fmt::format("run {} overflows its row", row));
        if (head & 0x80) {
          if (count * size_t(bpc) > end - at) return fail(fmt::format("run {} is cut short", row));
          for (size_t k = 0; k < count; ++k, at += size_t(bpc)) out[x++] = unit(at);
        } else {
          if (size_t(bpc) > end - at) return fail(fmt::format("run {} is cut short", row));
          std::fill(out + x, out + x + count, unit(at));
          x += count;
          at += size_t(bpc);
        }
      }
    }
  }
  SgiPixels px;
  px.width = width;
  px.height = height;
  px.rgba.resize(size_t(width) * size_t(height) * 4);
  for (int y = 0; y < height; ++y) {
    const size_t row = size_t(height - 1 - y);  // the file's rows run bottom first
    for (int x = 0; x < width; ++x) {
      auto at = [&](int c) { return plane[(size_t(c) * size_t(height) + row) * size_t(width) + size_t(x)]; };
      uint8_t* o = &px.rgba[(size_t(y) * size_t(width) + size_t(x)) * 4];
      const bool grey = channels <= 2;
      o[0] = at(0);
      o[1] = grey ? at(0) : at(1);
      o[2] = grey ? at(0) : at(2);
      o[3] = channels == 2 ? at(1) : channels == 4 ? at(3) : 255;
    }
  }
  return px;
}

}  // namespace sv::texture
