// For the PNG targets: libpng rejects a critical chunk whose CRC does not match, so almost every
// mutation of a PNG would stop at the first chunk it touches. withPngCrcs returns the input with
// each chunk's CRC recomputed (as far as the chunk lengths fit), so that mutations reach the
// decoder behind the check; truncated and malformed chunk streams still fail as before.
// Based on: the PNG specification (ISO/IEC 15948:2004), §5.3 (chunk layout: 4-byte big-endian
// length, 4-byte type, data, CRC-32 of type and data) and Annex D (CRC-32, polynomial 0xEDB88320
// reflected, initial and final XOR 0xFFFFFFFF).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace sv::fuzz {

inline uint32_t pngCrc(const uint8_t* data, size_t size) {
  static const std::array<uint32_t, 256> table = [] {
    std::array<uint32_t, 256> t{};
    for (uint32_t n = 0; n < 256; ++n) {
      uint32_t c = n;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[n] = c;
    }
    return t;
  }();
  uint32_t c = 0xFFFFFFFFu;
  for (size_t i = 0; i < size; ++i) c = table[(c ^ data[i]) & 0xFF] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

// The bytes after the 8-byte signature are read as chunks; each that fits whole gets its CRC
// rewritten, and the first that does not ends the walk.
inline std::vector<uint8_t> withPngCrcs(const uint8_t* data, size_t size) {
  std::vector<uint8_t> bytes(data, data + size);
  size_t at = 8;
  while (at + 12 <= size) {
    const uint8_t* p = &bytes[at];
    const uint64_t length =
        uint64_t(p[0]) << 24 | uint64_t(p[1]) << 16 | uint64_t(p[2]) << 8 | p[3];
    if (length > size - at - 12) break;
    const uint32_t crc = pngCrc(p + 4, size_t(length) + 4);
    uint8_t* out = &bytes[at + 8 + size_t(length)];
    for (int k = 0; k < 4; ++k) out[k] = uint8_t(crc >> (24 - 8 * k));
    at += 12 + size_t(length);
  }
  return bytes;
}

}  // namespace sv::fuzz
