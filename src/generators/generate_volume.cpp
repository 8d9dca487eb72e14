// Generated volumes (SPEC §11 voxel arrays): the Marschner–Lobb test signal, the standard measure
// of a volume renderer's reconstruction (its analytic values are known everywhere).
#include <algorithm>
#include <cmath>

#include "generators/generator_common.h"
#include "synthvis/formats.h"
#include "synthvis/generators.h"

namespace sv::generators {

Scene generateVolume(const VolumeParams& p) {
  const int n = std::clamp(p.size, 8, 512);
  auto grid = std::make_shared<VolumeGrid>();
  VolumeGrid& g = *grid;
  g.nx = g.ny = g.nz = n;
  const float spacing = 2.0f / float(n - 1);
  g.spacing = {spacing, spacing, spacing};
  g.scale = 1.0f / 255;
  g.codes.resize(size_t(n) * size_t(n) * size_t(n));
  // Six seeded blobs: centres within the cube, radii 0.15 … 0.35.
  double blobs[6][4];
  uint64_t state = p.seed * 0x9E3779B97F4A7C15ull + 12345;
  auto uniform = [&](double a, double b) {
    state ^= state >> 12, state ^= state << 25, state ^= state >> 27;
    return a + (b - a) * double((state * 0x2545F4914F6CDD1Dull) >> 11) / double(1ull << 53);
  };
  for (auto& b : blobs)
    b[0] = uniform(-0.6, 0.6), b[1] = uniform(-0.6, 0.6), b[2] = uniform(-0.6, 0.6),
    b[3] = uniform(0.15, 0.35);
  std::vector<uint32_t> histogram(256, 0);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double x = -1 + 2.0 * i / (n - 1), y = -1 + 2.0 * j / (n - 1),
                     z = -1 + 2.0 * k / (n - 1);
        const double r2 = x * x + y * y + z * z;
        double v = r2 < 0.7 ? 0.8 * formats::marschnerLobb(x, y, z) * (1 - r2 / 0.7) : 0;
        for (const auto& b : blobs) {
          const double d2 =
              (x - b[0]) * (x - b[0]) + (y - b[1]) * (y - b[1]) + (z - b[2]) * (z - b[2]);
          v += 0.9 * std::exp(-d2 / (b[3] * b[3]));
        }
        const auto code = uint16_t(std::lrint(std::clamp(v, 0.0, 1.0) * 255));
        g.codes[g.at(i, j, k)] = code;
        ++histogram[code];
      }
  // The threshold below which 70 % of the samples lie: transparent there.
  uint64_t below = 0;
  int threshold = 0;
  while (threshold < 255 &&
         below + histogram[size_t(threshold)] <= uint64_t(0.7 * double(g.codes.size())))
    below += histogram[size_t(threshold++)];
  const float t = float(threshold) / 255;
  // The shell: a sphere about the centre holding every sample above the threshold, and a cell's
  // diagonal more (a trilinear value above it lies in a cell with such a corner).
  double reach = 0;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        if (g.codes[g.at(i, j, k)] > threshold) {
          const double x = -1 + 2.0 * i / (n - 1), y = -1 + 2.0 * j / (n - 1),
                       z = -1 + 2.0 * k / (n - 1);
          reach = std::max(reach, x * x + y * y + z * z);
        }
  reach = std::sqrt(reach) + std::sqrt(3.0) * spacing;
  Scene s;
  s.background = {0.02f, 0.02f, 0.03f};
  s.light.direction = {0.5f, -0.7f, -0.5f};
  s.light.ambient = 0.3f;
  VolumeObject v;
  v.name = p.opaque ? "volume (opaque)" : "volume";
  v.grid = grid;
  v.transform = Mat4::translation({-1, -1, -1});
  if (p.opaque)
    v.transfer = {{t, {0.9f, 0.75f, 0.55f}, 0}, {t + 1.0f / 255, {0.9f, 0.75f, 0.55f}, 1}};
  else
    v.transfer = {{t, {0.2f, 0.4f, 1}, 0},
                  {std::min(1.0f, t + 0.2f), {1, 0.7f, 0.3f}, 0.15f},
                  {1.0f, {1, 1, 0.9f}, 0.5f}};
  v.opacityUnit = spacing;
  // F = reach² − |q − (1, 1, 1)|² ≥ 0 inside, in the grid's own space [0, 2]³.
  if (p.shell) v.shell.push_back({-1, -1, -1, 0, 0, 0, 2, 2, 2, reach * reach - 3});
  s.volumes.push_back(std::move(v));
  s.volumeSettings.precomputedNormals = p.precomputedNormals;
  s.cameras.push_back(detail::benchCamera({2.0f, 1.6f, 2.3f}, {0, 0, 0}, 45, 0.1f, 100));
  return s;
}

}  // namespace sv::generators
