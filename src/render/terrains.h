// The scene's terrains for the terrain stage (src/terrain): which interpolation a frame draws each
// with, the caster over a terrain, the pass's plain inputs, and the polygon baseline's grid.
#pragma once

#include <vector>

#include "core/eye_rays.h"
#include "render/shading_tables.h"
#include "synthvis/render.h"
#include "terrain/caster.h"
#include "terrain/terrain_pass.h"

namespace sv::render {

// Terrain `t`'s interpolation under `filter` (RenderOptions::terrainFilter): the terrain's own,
// or the one the filter forces.
terrain::Interpolation interpolationFor(const scene::Terrain& t,
                                        RenderOptions::TerrainFilter filter);

// The caster over terrain `t` (its heights, the pyramid of `interp`, its placement).
terrain::Caster casterOf(const scene::Terrain& t, terrain::Interpolation interp);

// The scene's terrains as a frame seen along `rays` draws them (terrain::TerrainPass's inputs):
// `shading` gives each its material, `options` the interpolation, the level of detail and the
// raster the pixel's size is measured on.
std::vector<terrain::TerrainDraw> terrainDraws(const scene::Scene& scene, const EyeRays& rays,
                                               const ShadingTables& shading,
                                               const RenderOptions& options);

// Terrain `t` as its full-resolution triangle grid, appended to `out` (tessellatedScene: the
// polygon and llvmpipe baselines): vertices on the table's samples, normals of the surface
// `options` interpolates, the image's texture coordinates or the ramp's colours, a material of
// its own (the terrain's, with the image as its texture, double-sided).
void appendTerrainGrid(const scene::Terrain& t, const RenderOptions& options, scene::Scene& out);

}  // namespace sv::render
