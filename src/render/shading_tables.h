// The shading stage's tables for a frame (SPEC §7–§8): every material as pixel shading reads it,
// and the lights and fog in eye space.
#pragma once

#include <vector>

#include "shade/shading.h"
#include "synthvis/render.h"

namespace sv::render {

// The shading stage's view of the scene: materials (two variants each — with and without normals
// to light per pixel), and lights and fog in eye space.
struct ShadingTables {
  std::vector<shade::MaterialShading> materials;  // [2·(material + 1) + hasNormals]
  shade::Environment environment;
  bool any = false;  // some draw needs pixel shading (or fog)

  const shade::MaterialShading* of(int material, bool hasNormals) const {
    return &materials[size_t(2 * (material + 1) + (hasNormals ? 1 : 0))];
  }
};

// Fills `out` for `scene` seen through `view` (world → eye), with the options' texture filter for
// materials that do not choose one.
void buildShading(const scene::Scene& scene, const RenderOptions& options, const Mat4& view,
                  ShadingTables& out);

}  // namespace sv::render
