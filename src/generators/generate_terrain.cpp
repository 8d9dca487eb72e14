// BENCH.md `terrain`: the ground of a flight simulator — a fractal height field seen from 300 m
// toward the horizon, draped, lit and hazy (SPEC §11–§12).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>

#include "formats/heights.h"
#include "generators/generator_common.h"
#include "synthvis/generators.h"
#include "terrain/ground.h"
#include "texture/texture.h"

namespace sv::generators {

Result<Scene> generateTerrain(const TerrainParams& p) {
  constexpr double kExtent = 40960, kRelief = 1200;
  const auto start = std::chrono::steady_clock::now();
  Result<HeightField> field = formats::generateFractal(p.size, kExtent / std::max(p.size - 1, 1),
                                                       kRelief, uint32_t(p.seed));
  if (!field) return field.error();
  field->loadMs =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  const std::shared_ptr<const HeightField> heights = terrain::prepareGround(
      std::move(field.value()),
      p.bicubic ? terrain::Interpolation::bicubic : terrain::Interpolation::bilinear);
  const HeightField& f = *heights;
  Scene s;
  // The draped image: the height's colour (greens low, rock high, snow on the peaks) times seed
  // 001's noise, 2048² over the map (20 m texels).
  constexpr int kImage = 2048;
  const texture::Level noise = texture::generateTexture(
      texture::Pattern::noise, kImage, {0.75f, 0.75f, 0.75f, 1}, {1, 1, 1, 1}, uint32_t(p.seed));
  texture::Level image = noise;
  const terrain::Interpolation interp = terrain::Interpolation::bilinear;
  for (int y = 0; y < kImage; ++y)
    for (int x = 0; x < kImage; ++x) {
      const double gx = (x + 0.5) / kImage * (f.width - 1),
                   gy = (y + 0.5) / kImage * (f.height - 1);
      const double t = std::clamp(terrain::interpolate(f, interp, gx, gy) / kRelief, 0.0, 1.0);
      double r, g, b;  // linear
      if (t < 0.45)
        r = 0.06 + 0.10 * t, g = 0.12 + 0.10 * t, b = 0.04;
      else if (t < 0.75)
        r = 0.16 + 0.2 * (t - 0.45), g = 0.15, b = 0.09 + 0.1 * (t - 0.45);
      else if (t < 0.88)
        r = 0.30, g = 0.29, b = 0.27;
      else
        r = 0.80, g = 0.82, b = 0.85;
      texture::Texel& texel = image.texels[size_t(y) * kImage + size_t(x)];
      const texture::Texel& n = noise.texels[size_t(y) * kImage + size_t(x)];
      texel.r = uint16_t(std::lround(std::min(1.0, r * n.r / 65535.0) * 65535));
      texel.g = uint16_t(std::lround(std::min(1.0, g * n.g / 65535.0) * 65535));
      texel.b = uint16_t(std::lround(std::min(1.0, b * n.b / 65535.0) * 65535));
      texel.a = 65535;
    }
  s.textures.push_back(
      {"terrain image", std::make_shared<texture::Texture>(std::move(image), texture::Wrap::clamp,
                                                           texture::Wrap::clamp)});
  Material m;
  m.name = "ground";
  m.phong = true;
  s.materials.push_back(m);
  Terrain t;
  t.name = "fractal";
  t.heights = heights;
  t.bicubic = p.bicubic;
  t.material = 0;
  t.image = 0;
  t.origin[0] = 0.5 * (f.originU + f.eastU());
  t.origin[1] = 0.5 * (f.originV + f.southV());
  // The image's outer edges: half a texel beyond... the map's extent exactly.
  t.imageBounds[0] = f.originU, t.imageBounds[1] = f.southV();
  t.imageBounds[2] = f.eastU(), t.imageBounds[3] = f.originV;
  s.terrains.push_back(t);
  // The camera 300 m above the ground at the centre, looking north 8° down.
  const double below = terrain::interpolate(f, interp, 0.5 * (f.width - 1), 0.5 * (f.height - 1));
  Camera c;
  c.name = "flight";
  c.position = {0, float(below + 300), 0};
  const float pitch = 8 * std::numbers::pi_v<float> / 180;
  c.target = {0, c.position.y - std::sin(pitch) * 1000, -std::cos(pitch) * 1000};
  c.yfovDegrees = 60;
  c.znear = 1;
  c.zfar = 60000;
  s.cameras.push_back(c);
  s.light.direction = {0.7f, -0.3f, 0.45f};  // a low sun ahead, from the north-west
  s.light.ambient = 0.3f;
  s.background = {0.55f, 0.63f, 0.75f};
  s.fog.enabled = true;
  s.fog.color = s.background;
  s.fog.beta = float(1.0 / 12000);
  return s;
}

}  // namespace sv::generators
