// BENCH.md `grazing`: seed 001's figures 6–9 — a textured ground plane seen at a grazing angle and
// textured cubes — for the texture samplers' cost where their level of detail varies most.
#include <cmath>
#include <memory>
#include <numbers>
#include <utility>

#include "formats/primitives.h"
#include "generators/generator_common.h"
#include "synthvis/generators.h"
#include "texture/texture.h"

namespace sv::generators {

Scene generateGrazing(const GrazingParams& p) {
  Scene s;
  auto addTexture = [&](const char* name, texture::Pattern pattern, int size, texture::Color4 a,
                        texture::Color4 b) {
    texture::Level level = texture::generateTexture(pattern, size, a, b, uint32_t(p.seed));
    s.textures.push_back(
        {name, std::make_shared<texture::Texture>(std::move(level), texture::Wrap::repeat,
                                                  texture::Wrap::repeat)});
  };
  // The ground: seed 001's random texture, 2.4 cm texels repeated every 12.5 m; the cubes: squares.
  addTexture("random", texture::Pattern::noise, 512, {0.10f, 0.16f, 0.06f, 1},
             {0.42f, 0.40f, 0.22f, 1});
  addTexture("squares", texture::Pattern::squares, 256, {0.75f, 0.18f, 0.10f, 1},
             {0.92f, 0.90f, 0.82f, 1});
  Material ground;
  ground.name = "ground";
  ground.texture = 0;
  ground.uvScale = {80, 80};
  Material cube;
  cube.name = "cube";
  cube.texture = 1;
  cube.phong = true;
  cube.specular = 0.25f;
  cube.shininess = 24;
  s.materials = {ground, cube};

  Mesh plane = formats::detail::makePlane(1000, 1000, 1, 1);
  plane.name = "ground";
  plane.material = 0;
  s.meshes.push_back(std::move(plane));
  s.instances.push_back({0, Mat4{}});
  // Five cubes (thirty faces), 2 to 6 m, 9 to 90 m away, alternately left and right.
  const struct {
    float size, x, z, yawDegrees;
  } cubes[] = {
      {2, -3, -9, 25}, {3, 4.5f, -16, -35}, {4, -9, -30, 10}, {5, 12, -55, 50}, {6, -4, -90, -15}};
  for (const auto& c : cubes) {
    Mesh box = formats::detail::makeBox({c.size, c.size, c.size});
    box.name = "cube";
    box.material = 1;
    s.meshes.push_back(std::move(box));
    s.instances.push_back(
        {int(s.meshes.size() - 1),
         Mat4::translation({c.x, c.size / 2, c.z}) *
             Mat4::rotation({0, 1, 0}, c.yawDegrees * std::numbers::pi_v<float> / 180)});
  }

  s.cameras.push_back({.name = "grazing",
                       .position = {0, 2, 0},
                       .target = {0, 1.55f, -40},
                       .yfovDegrees = 45,
                       .znear = 0.5f,
                       .zfar = 2000});
  s.light.direction = {-0.45f, -1.0f, -0.35f};
  s.light.color = {1.0f, 0.97f, 0.9f};
  s.light.ambient = 0.35f;
  s.background = {0.62f, 0.70f, 0.80f};
  if (p.fog) {
    // Light haze toward the horizon: the background colour, halving every 250 m.
    s.fog.enabled = true;
    s.fog.color = s.background;
    s.fog.beta = 0.004f;
  }
  return s;
}

}  // namespace sv::generators
