// What the volume readers share (volume_samples.h): sample types and the samples as codes.
#include "formats/volume_samples.h"

#include <bit>
#include <cmath>
#include <vector>

namespace sv::formats::volumes {

size_t sizeOf(Type t) {
  switch (t) {
    case Type::u8:
    case Type::i8:
      return 1;
    case Type::u16:
    case Type::i16:
      return 2;
    case Type::u32:
    case Type::i32:
    case Type::f32:
      return 4;
    case Type::f64:
      return 8;
  }
  return 1;
}

VolumeGrid sizedGrid(int64_t nx, int64_t ny, int64_t nz, size_t maxSamples) {
  for (int64_t n : {nx, ny, nz})
    if (n < 2 || n > kMaxVolumeSide)
      fail(fmt::format("{} × {} × {} samples: each side must be 2 … {}", nx, ny, nz,
                       kMaxVolumeSide));
  if (uint64_t(nx) * uint64_t(ny) * uint64_t(nz) > maxSamples)
    fail(fmt::format("{} × {} × {} samples: more than {}", nx, ny, nz, maxSamples));
  VolumeGrid g;
  g.nx = int(nx), g.ny = int(ny), g.nz = int(nz);
  return g;
}

void readSamples(VolumeGrid& g, Source& in, Type type, bool bigEndian) {
  const size_t n = size_t(g.nx) * size_t(g.ny) * size_t(g.nz), size = sizeOf(type);
  if (in.most() < uint64_t(n) * size)
    fail(fmt::format("truncated: {} samples of {} bytes need {} bytes, the file holds at most {}",
                     n, size, uint64_t(n) * size, in.most()));
  g.codes.resize(n);
  std::vector<double> wide;
  if (size > 2 || type == Type::f32) wide.resize(n);
  constexpr size_t kChunk = 1 << 16;
  std::vector<unsigned char> buffer(kChunk * size);
  for (size_t first = 0; first < n; first += kChunk) {
    const size_t count = std::min(kChunk, n - first);
    in.read(buffer.data(), count * size, "the samples");
    for (size_t i = 0; i < count; ++i) {
      unsigned char b[8];
      std::memcpy(b, buffer.data() + i * size, size);
      if (bigEndian != (std::endian::native == std::endian::big)) std::reverse(b, b + size);
      auto as = [&]<class T>(T) {
        T v;
        std::memcpy(&v, b, sizeof v);
        return v;
      };
      const size_t at = first + i;
      switch (type) {
        case Type::u8:
          g.codes[at] = b[0];
          break;
        case Type::i8:
          g.codes[at] = uint16_t(int(as(int8_t{})) + 128);
          break;
        case Type::u16:
          g.codes[at] = as(uint16_t{});
          break;
        case Type::i16:
          g.codes[at] = uint16_t(int(as(int16_t{})) + 32768);
          break;
        case Type::u32:
          wide[at] = as(uint32_t{});
          break;
        case Type::i32:
          wide[at] = as(int32_t{});
          break;
        case Type::f32:
          wide[at] = as(float{});
          break;
        case Type::f64:
          wide[at] = as(double{});
          break;
      }
    }
  }
  g.offset = type == Type::i8 ? -128.0f : type == Type::i16 ? -32768.0f : 0.0f;
  g.scale = 1;
  if (wide.empty()) return;
  double lo = INFINITY, hi = -INFINITY;
  for (double v : wide) {
    if (!std::isfinite(v)) fail("a sample is not finite");
    lo = std::min(lo, v), hi = std::max(hi, v);
  }
  const double step = hi > lo ? (hi - lo) / 65535 : 1;
  if (!std::isfinite(step) || !std::isfinite(float(lo)) || !(float(step) > 0))
    fail("the samples' range is not representable");
  for (size_t i = 0; i < n; ++i) g.codes[i] = uint16_t(std::lrint((wide[i] - lo) / step));
  g.offset = float(lo);
  g.scale = float(step);
}

void rescale(VolumeGrid& g, double slope, double intercept) {
  if (!std::isfinite(slope) || !std::isfinite(intercept) || slope == 0) return;
  if (slope < 0) {
    const uint16_t top = *std::max_element(g.codes.begin(), g.codes.end());
    for (uint16_t& c : g.codes) c = uint16_t(top - c);
    g.offset = float(slope * (double(g.offset) + double(g.scale) * top) + intercept);
    g.scale = float(-slope * g.scale);
  } else {
    g.offset = float(slope * g.offset + intercept);
    g.scale = float(slope * g.scale);
  }
  if (!std::isfinite(g.offset) || !(g.scale > 0) || !std::isfinite(g.scale))
    fail("its value scaling (scl_slope, scl_inter) is not representable");
}

float spacingOf(double v) {
  return std::isfinite(v) && std::fabs(v) > 1e-20 && std::fabs(v) < 1e20 ? float(std::fabs(v))
                                                                         : 1.0f;
}

bool gzipped(const std::string& bytes) {
  return bytes.size() >= 2 && uint8_t(bytes[0]) == 0x1f && uint8_t(bytes[1]) == 0x8b;
}

}  // namespace sv::formats::volumes
