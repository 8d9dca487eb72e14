// BENCH.md `lights`: light points over the `layers` D = 1 scene (synthvis/generators.h).
#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <random>

#include "generators/generator_common.h"
#include "synthvis/formats.h"
#include "synthvis/generators.h"

namespace sv::generators {

Result<Scene> generateLights(const LightsParams& p) {
  constexpr int kMaxCount = 1 << 22;
  if (p.count < 0 || p.count > kMaxCount)
    return Error{"", "", fmt::format("lights: count {} is not in 0…{}", p.count, kMaxCount)};
  LayersParams l;
  l.layers = 1;
  l.seed = p.seed;
  l.width = p.width;
  l.height = p.height;
  Scene s = generateLayers(l);
  if (!p.starCatalog.empty()) {
    Result<std::vector<Star>> stars = formats::loadStarCatalog(p.starCatalog);
    if (!stars.ok()) return stars.error();
    s.stars.stars = std::move(stars.value());
    if (s.stars.stars.size() > size_t(p.count)) s.stars.stars.resize(size_t(p.count));
  }
  // Scene units: the grid at distance 2, lights at 0.15 … 1.9; a 1-cd light at distance 1 carries
  // Φ = 4 pixels (2.9 px across), the nearest clamp at 4 px, the farthest at 1.5.
  s.lightSettings.exposure = 4;
  s.lightSettings.minSize = 1.5f;
  s.lightSettings.maxSize = 4;
  LightAppearance edge, centre, flasher, city;
  edge.name = "edge";
  edge.color = {1, 0.85f, 0.6f};
  edge.intensity = 1;
  edge.directional = true;
  edge.direction = {0, 0.05f, 1};  // toward the eye
  edge.horizontalLobe = 60;
  edge.verticalLobe = 30;
  centre.name = "centreline";
  centre.intensity = 0.8f;
  flasher = edge;
  flasher.name = "flasher";
  flasher.color = {0.9f, 0.95f, 1};
  flasher.intensity = 4;
  flasher.blink = {.period = 0.5f, .phase = 0, .onFraction = 0.2f};
  city.name = "city";
  city.color = {1, 0.6f, 0.25f};
  city.intensity = 0.6f;
  s.lightAppearances = {edge, centre, flasher, city};

  const int lights = p.count - int(s.stars.stars.size());
  const int strings = lights / 4;
  const double aspect = double(p.width) / double(p.height);
  const double tanY = std::tan(std::numbers::pi / 6), tanX = tanY * aspect;
  // Runways: 8 side by side on the plane y = −0.2 (below the eye), each an edge row either side
  // and a centreline of flashers running toward the far end, from distance 0.15 to 1.9.
  constexpr int kRunways = 8, kRows = 3;
  const int perRow = std::max(1, strings / (kRunways * kRows));
  for (int r = 0; r < kRunways && int(s.lightPoints.size()) < strings; ++r) {
    const double x0 = (double(r) - 3.5) * 0.09;
    for (int row = 0; row < kRows; ++row)
      for (int k = 0; k < perRow; ++k) {
        const double z = 0.15 + 1.75 * (double(k) + 0.5) / double(perRow);
        LightPoint lp;
        lp.position = {float(x0 + (double(row) - 1) * 0.02), -0.2f, float(-z)};
        lp.appearance = row == 1 ? (k % 8 == 0 ? 2u : 1u) : 0u;
        lp.phase = -float(k) / float(perRow);
        s.lightPoints.push_back(lp);
      }
  }
  // The city: uniform over the screen, at view distances uniform in [0.15, 1.9].
  std::mt19937_64 rng(p.seed ^ 0x11947u);
  std::uniform_real_distribution<double> u(0, 1);
  while (int(s.lightPoints.size()) < lights) {
    const double z = 0.15 + 1.75 * u(rng);
    const double sx = 2 * u(rng) - 1, sy = 2 * u(rng) - 1;
    LightPoint lp;
    lp.position = {float(sx * tanX * z), float(sy * tanY * z), float(-z)};
    lp.appearance = 3;
    s.lightPoints.push_back(lp);
  }
  return s;
}

}  // namespace sv::generators
