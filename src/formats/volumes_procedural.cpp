// Procedural volumes a scene file may name instead of a file (SPEC §11 voxel arrays): the
// Marschner–Lobb test signal, the standard measure of a volume renderer's reconstruction (its
// analytic values are known everywhere), and a seeded cloud layer of fractal value noise.
#include <algorithm>
#include <cmath>

#include "synthvis/formats.h"

namespace sv::formats {

using scene::VolumeGrid;

double marschnerLobb(double x, double y, double z) {
  constexpr double kFm = 6, kAlpha = 0.25;
  const double r = std::sqrt(x * x + y * y);
  const double rho = std::cos(2 * M_PI * kFm * std::cos(M_PI * r / 2));
  return (1 - std::sin(M_PI * z / 2) + kAlpha * (1 + rho)) / (2 * (1 + kAlpha));
}

VolumeGrid marschnerLobbGrid(int size, int bits) {
  size = std::clamp(size, 2, 1024);
  const double top = bits == 16 ? 65535 : 255;
  VolumeGrid g;
  g.nx = g.ny = g.nz = size;
  const float spacing = 2.0f / float(size - 1);
  g.spacing = {spacing, spacing, spacing};
  g.offset = 0;
  g.scale = float(1 / top);
  g.codes.resize(size_t(size) * size_t(size) * size_t(size));
  for (int k = 0; k < size; ++k)
    for (int j = 0; j < size; ++j)
      for (int i = 0; i < size; ++i) {
        const double v = marschnerLobb(-1 + 2.0 * i / (size - 1), -1 + 2.0 * j / (size - 1),
                                       -1 + 2.0 * k / (size - 1));
        g.codes[g.at(i, j, k)] = uint16_t(std::lrint(std::clamp(v, 0.0, 1.0) * top));
      }
  return g;
}

namespace {

// A lattice value in [0, 1) for integer point (x, y, z) of octave `o` (a 64-bit mix of the seed).
double lattice(int64_t x, int64_t y, int64_t z, int o, uint64_t seed) {
  uint64_t h = seed ^ (uint64_t(x) * 0x9E3779B97F4A7C15ull) ^
               (uint64_t(y) * 0xC2B2AE3D27D4EB4Full) ^ (uint64_t(z) * 0x165667B19E3779F9ull) ^
               (uint64_t(o) << 56);
  h ^= h >> 33, h *= 0xFF51AFD7ED558CCDull, h ^= h >> 33, h *= 0xC4CEB9FE1A85EC53ull, h ^= h >> 33;
  return double(h >> 11) / double(1ull << 53);
}

// Value noise at (x, y, z): the lattice smoothly interpolated (smoothstep weights).
double valueNoise(double x, double y, double z, int o, uint64_t seed) {
  const double fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
  auto smooth = [](double t) { return t * t * (3 - 2 * t); };
  const double tx = smooth(x - fx), ty = smooth(y - fy), tz = smooth(z - fz);
  const auto ix = int64_t(fx), iy = int64_t(fy), iz = int64_t(fz);
  double v = 0;
  for (int c = 0; c < 8; ++c) {
    const double w = (c & 1 ? tx : 1 - tx) * (c & 2 ? ty : 1 - ty) * (c & 4 ? tz : 1 - tz);
    v += w * lattice(ix + (c & 1), iy + (c >> 1 & 1), iz + (c >> 2 & 1), o, seed);
  }
  return v;
}

}  // namespace

VolumeGrid cloudGrid(int size, uint64_t seed, float cover) {
  size = std::clamp(size, 8, 1024);
  VolumeGrid g;
  g.nx = g.nz = size;
  g.ny = std::max(2, size / 4);
  g.scale = 1.0f / 255;
  g.codes.resize(size_t(g.nx) * size_t(g.ny) * size_t(g.nz));
  const double feature = size / 6.0;  // the largest puffs, in samples
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j) {
      // Thin toward the layer's bottom and top (a parabola over its height).
      const double h = (j + 0.5) / g.ny, profile = 4 * h * (1 - h);
      for (int i = 0; i < g.nx; ++i) {
        double n = 0, amplitude = 0.5, norm = 0;
        for (int o = 0; o < 4; ++o) {
          const double f = double(1 << o) / feature;
          n += amplitude * valueNoise(i * f, j * f * 1.5, k * f, o, seed);
          norm += amplitude;
          amplitude *= 0.5;
        }
        const double d = std::clamp((n / norm * profile - cover) / (1 - cover) * 2.5, 0.0, 1.0);
        g.codes[g.at(i, j, k)] = uint16_t(std::lrint(d * 255));
      }
    }
  return g;
}

}  // namespace sv::formats
