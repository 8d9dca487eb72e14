// Generated volumes (SPEC §11 voxel arrays): the Marschner–Lobb test signal, the standard measure
// of a volume renderer's reconstruction (its analytic values are known everywhere).
#include <algorithm>
#include <cmath>

#include "synthvis/generators.h"

namespace sv::scene {

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

}  // namespace sv::scene
