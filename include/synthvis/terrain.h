// What a simulator host asks of the ground (issue 29 item 5), answered by the same cast that
// draws it (terrain/caster.h), so a query and the picture agree exactly: the height of the
// terrain under a point, and the first point where a line of sight meets it.
//
// World coordinates as the scene places terrain (scene.h, Terrain): y up. With several terrains
// the nearest (line of sight) or the highest (height) answers. `filter` chooses the interpolation
// as RenderOptions::terrainFilter does, so a query matches a frame rendered with the same choice.
#pragma once

#include <optional>

#include "synthvis/render.h"
#include "synthvis/scene.h"

namespace sv {

struct TerrainHeight {
  double elevation = 0;  // the ground's height above the base at the point, metres
  double above = 0;      // the point's height above the ground (negative: below it)
  int terrain = 0;       // index into Scene::terrains
};
// The ground under (or over) `point`, along the base's normal there; nothing where no terrain
// covers it.
std::optional<TerrainHeight> terrainHeight(
    const scene::Scene& scene, double x, double y, double z,
    RenderOptions::TerrainFilter filter = RenderOptions::TerrainFilter::scene);

struct TerrainHit {
  double x = 0, y = 0, z = 0;  // world
  double fraction = 0;         // along the segment, 0 … 1
  int terrain = 0;
};
// The first point of the segment from `from` to `to` on the ground (or inside it); nothing when
// the line of sight is clear.
std::optional<TerrainHit> lineOfSight(
    const scene::Scene& scene, const double from[3], const double to[3],
    RenderOptions::TerrainFilter filter = RenderOptions::TerrainFilter::scene);

}  // namespace sv
