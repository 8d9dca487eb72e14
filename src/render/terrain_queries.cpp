// The host's terrain queries (synthvis/terrain.h), through terrain::Caster.
#include <cmath>

#include "render/terrains.h"
#include "synthvis/terrain.h"

namespace sv {
using render::casterOf;
using render::interpolationFor;

std::optional<TerrainHeight> terrainHeight(const scene::Scene& scene, double x, double y,
                                           double z, RenderOptions::TerrainFilter filter) {
  std::optional<TerrainHeight> best;
  for (size_t i = 0; i < scene.terrains.size(); ++i) {
    const scene::Terrain& t = scene.terrains[i];
    if (!t.heights) continue;
    const terrain::Caster c = casterOf(t, interpolationFor(t, filter));
    const terrain::Caster::MapPoint m = c.toMap({x, y, z});
    const double h = c.surface(m.gx, m.gy);
    if (std::isnan(h)) continue;
    if (!best || h > best->elevation) best = TerrainHeight{h, m.h - h, int(i)};
  }
  return best;
}

std::optional<TerrainHit> lineOfSight(const scene::Scene& scene, const double from[3],
                                      const double to[3], RenderOptions::TerrainFilter filter) {
  std::optional<TerrainHit> best;
  const Vec3d a{from[0], from[1], from[2]};
  const Vec3d d = Vec3d{to[0], to[1], to[2]} - a;
  for (size_t i = 0; i < scene.terrains.size(); ++i) {
    const scene::Terrain& t = scene.terrains[i];
    if (!t.heights) continue;
    const terrain::Caster c = casterOf(t, interpolationFor(t, filter));
    terrain::CastCounters counters;
    const double s = c.cast(a, d, 0, 1, counters);
    if (std::isnan(s) || (best && s >= best->fraction)) continue;
    const Vec3d p = a + d * s;
    best = TerrainHit{p.x, p.y, p.z, s, int(i)};
  }
  return best;
}

}  // namespace sv
