// Shared by the BENCH.md scene generators (generate_*.cpp).
#pragma once

#include <cmath>
#include <random>

#include "synthvis/math.h"
#include "synthvis/scene.h"

namespace sv::generators {
// The generators build the database's records throughout.
using namespace sv::scene;  // NOLINT(google-build-using-namespace)
}  // namespace sv::generators

namespace sv::generators::detail {

// BENCH.md's random vertex colour: each channel a display value uniform in [64, 255], stored as
// linear light (the sRGB decoding of IEC 61966-2-1).
template <class Rng>
Vec4 randomBenchColor(Rng& rng) {
  auto channel = [&] {
    const double v = std::uniform_int_distribution<int>(64, 255)(rng) / 255.0;
    return float(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
  };
  const float r = channel(), g = channel(), b = channel();
  return {r, g, b, 1};
}

// The camera a generated scene is seen through: named "bench", looking from `position` at
// `target`, vertical field of view `yfovDegrees`, depth range [znear, zfar].
inline Camera benchCamera(Vec3 position, Vec3 target, float yfovDegrees, float znear, float zfar) {
  Camera cam;
  cam.name = "bench";
  cam.position = position;
  cam.target = target;
  cam.yfovDegrees = yfovDegrees;
  cam.znear = znear;
  cam.zfar = zfar;
  return cam;
}

}  // namespace sv::generators::detail
