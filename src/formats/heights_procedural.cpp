// Height tables from numbers and from a seed: quantization of any heights to the 16-bit table
// (SPEC §11 fixes no precision; synthvis/height_field.h), and the seeded fractal generator.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "formats/heights.h"

namespace sv::formats {

Result<HeightField> quantize(const std::vector<double>& values, int width, int height,
                             const std::string& source) {
  if (width < 2 || height < 2)
    return Error{
        source, "",
        fmt::format("a height table needs at least 2 × 2 samples, not {} × {}", width, height)};
  if (width > kMaxHeightSide || height > kMaxHeightSide ||
      int64_t(width) * height > kMaxHeightSamples)
    return Error{source, "",
                 fmt::format("{} × {} heights exceed the limit of {} a side", width, height,
                             kMaxHeightSide)};
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double v : values)
    if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  if (!(lo <= hi)) return Error{source, "", "the height table holds no valid height"};
  if (hi - lo > 1e7 || std::fabs(lo) > 1e7 || std::fabs(hi) > 1e7)
    return Error{source, "", fmt::format("heights from {} to {} are beyond ±10 000 km", lo, hi)};
  HeightField f;
  f.width = width;
  f.height = height;
  f.source = source;
  f.offset = lo;
  f.scale = hi > lo ? (hi - lo) / 65535.0 : 1.0;
  f.q.resize(size_t(width) * size_t(height));
  const double inv = 1.0 / f.scale;
  for (size_t k = 0; k < f.q.size(); ++k) {
    const double v = std::isfinite(values[k]) ? values[k] : lo;
    f.q[k] = uint16_t(std::clamp(std::lround((v - lo) * inv), 0L, 65535L));
  }
  return f;
}

namespace {

// A hash of (seed, i, j) to [−1, 1): the displacement at a point depends on the point alone, so
// the table does not depend on the order it is filled in.
double noise(uint32_t seed, uint32_t i, uint32_t j) {
  uint64_t h = (uint64_t(seed) << 32) ^ (uint64_t(i) * 0x9E3779B97F4A7C15ull) ^
               (uint64_t(j) * 0xC2B2AE3D27D4EB4Full);
  h ^= h >> 31;
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 27;
  h *= 0x94D049BB133111EBull;
  h ^= h >> 33;
  return double(h >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

}  // namespace

Result<HeightField> generateFractal(int size, double spacing, double relief, uint32_t seed) {
  const std::string source = fmt::format("fractal(size {}, seed {})", size, seed);
  if (size < 2 || size > kMaxHeightSide)
    return Error{"", "", fmt::format("terrain size {} is outside 2 … {}", size, kMaxHeightSide)};
  if (!(spacing > 0) || !(relief > 0) || !std::isfinite(spacing) || !std::isfinite(relief))
    return Error{"", "", "terrain spacing and relief must be positive"};
  // Midpoint displacement (diamond–square) on the smallest 2^k + 1 grid holding the table, the
  // displacement × 0.6 with each level (height_field.h), then cropped.
  int n = 1;
  while (n + 1 < size) n *= 2;
  const int m = n + 1;
  std::vector<float> g(size_t(m) * size_t(m), 0.0f);
  auto at = [&](int x, int y) -> float& { return g[size_t(y) * size_t(m) + size_t(x)]; };
  double amplitude = 1.0;
  for (int step = n; step > 1; step /= 2, amplitude *= 0.6) {
    const int h = step / 2;
    for (int y = h; y < m; y += step)  // diamond: the squares' centres
      for (int x = h; x < m; x += step)
        at(x, y) = float(
            0.25 * (at(x - h, y - h) + at(x + h, y - h) + at(x - h, y + h) + at(x + h, y + h)) +
            amplitude * noise(seed, uint32_t(x), uint32_t(y)));
    for (int y = 0; y < m; y += h)  // square: the edges' midpoints
      for (int x = (y / h % 2 == 0) ? h : 0; x < m; x += step) {
        double sum = 0;
        int count = 0;
        if (x >= h) sum += at(x - h, y), ++count;
        if (x + h < m) sum += at(x + h, y), ++count;
        if (y >= h) sum += at(x, y - h), ++count;
        if (y + h < m) sum += at(x, y + h), ++count;
        at(x, y) = float(sum / count + amplitude * noise(seed, uint32_t(x), uint32_t(y)));
      }
  }
  // Ridges: |·| folds the low-frequency relief into valleys and crests, as mountains look. Folded
  // in place and quantized straight from the grid over [0, relief] (no table of doubles: at
  // 16384² that would be 2 GB more).
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      float& v = at(x, y);
      v = float(v + 1.5 * (0.5 - std::fabs(double(v))));
      lo = std::min(lo, v), hi = std::max(hi, v);
    }
  HeightField hf;
  hf.width = hf.height = size;
  hf.source = source;
  hf.scale = relief / 65535.0;
  hf.offset = 0;
  hf.spacingU = hf.spacingV = spacing;
  hf.originU = -0.5 * (size - 1) * spacing;
  hf.originV = 0.5 * (size - 1) * spacing;
  hf.q.resize(size_t(size) * size_t(size));
  const double toCode = hi > lo ? 65535.0 / (double(hi) - lo) : 0.0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      hf.q[size_t(y) * size_t(size) + size_t(x)] =
          uint16_t(std::clamp(std::lround((double(at(x, y)) - lo) * toCode), 0L, 65535L));
  return hf;
}

}  // namespace sv::formats
