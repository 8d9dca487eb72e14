// Scenes the render tests build by hand.
#pragma once

#include "synthvis/generators.h"
#include "synthvis/scene.h"

namespace sv::tests {

// The camera at the origin looking down −z (60° yfov, near 0.1, far `zfar`), no light, the
// background `background`; nothing else.
inline scene::Scene emptyScene(float zfar = 100, Vec3 background = {0, 0, 0}) {
  scene::Scene s;
  scene::Camera cam;
  cam.position = {0, 0, 0};
  cam.target = {0, 0, -1};
  cam.yfovDegrees = 60;
  cam.znear = 0.1f;
  cam.zfar = zfar;
  s.cameras.push_back(cam);
  s.light.enabled = false;
  s.background = background;
  return s;
}

// BENCH.md's terrain at 129² heights: a small fractal ground with its camera, light and haze.
inline scene::Scene smallTerrain() {
  generators::TerrainParams p;
  p.size = 129;
  return generators::generateTerrain(p).value();
}

}  // namespace sv::tests
