// Terrain in the frame: a tile pass (raster/tile_pass.h, stage `surfaces`) that ray casts the
// scene's height fields (terrain/caster.h) into each tile's depth and samples, after the opaque
// polygons and the free forms, shading each pixel once where its samples meet the ground.
//
// Based on: SPEC §12 (multi-level ray casting: the screen quadtree from the tile down to pixels,
// each window marched in depth from where its parent stopped — front to back, bounded by the
// farthest depth already in the window, so what polygons hide is never cast), §5 (one ray per
// sample, the frame's sample pattern: silhouettes and ridges anti-aliased with the polygons'),
// §7 (seed 001's planar texture: the draped image by the map plane's anchor and axes), §8.
#pragma once

#include <memory>
#include <vector>

#include "core/eye_rays.h"
#include "raster/tile_pass.h"
#include "render/camera.h"
#include "render/shading_tables.h"
#include "terrain/ground.h"

namespace sv::render {

// Terrain `t` as its full-resolution triangle grid, appended to `out` (tessellatedScene: the
// polygon and llvmpipe baselines): vertices on the table's samples, normals of the surface
// `options` interpolates, the image's texture coordinates or the ramp's colours, a material of
// its own (the terrain's, with the image as its texture, double-sided).
void appendTerrainGrid(const scene::Terrain& t, const RenderOptions& options, scene::Scene& out);

class TerrainPass final : public raster::TilePass {
 public:
  TerrainPass();
  ~TerrainPass() override;
  // The scene's terrains as `camera` sees them; `environment` must outlive the frame.
  // `interpolation` overrides each terrain's own when set (the CLI's --terrain-filter).
  void setTerrains(const scene::Scene& scene, const FrameCamera& camera,
                   const ShadingTables& shading, const RenderOptions& options);

  raster::PassStage stage() const override { return raster::PassStage::surfaces; }
  void prepare(const raster::PassFrame& frame) override;
  void drawTile(const raster::TileTarget& tile) override;
  void addStats(FrameStats& stats) const override;

 private:
  struct Drawn {  // one terrain as the frame draws it
    const terrain::Ground* ground;
    std::unique_ptr<terrain::Caster> caster;
    shade::MaterialShading material;
    float color[3];
    const texture::Texture* detail = nullptr;
    double detailSize = 10;
    double imageBounds[4];
    std::vector<scene::TerrainColorStop> ramp;
    double pixel = 0;  // a pixel's width per unit s in grid steps (terrain::Caster's levels of detail)
  };
  struct Scratch;
  struct alignas(64) WorkerStats {
    terrain::CastCounters counts;
  };

  void castWindow(Scratch& w, const Drawn& t, int x0, int y0, int size, double start) const;
  void castPixel(Scratch& w, const Drawn& t, int x, int y, double start) const;
  void shadeHits(Scratch& w, const Drawn& t, const raster::TileTarget& tile) const;
  std::vector<Drawn> terrains_;
  const shade::Environment* environment_ = nullptr;
  EyeRays rays_;  // the camera's rays and depths (its raster set by prepare)
  int width_ = 0, height_ = 0, samples_ = 1;
  double offsetX_[64] = {}, offsetY_[64] = {};
  std::vector<std::unique_ptr<Scratch>> scratch_;
  std::vector<WorkerStats> stats_;
  size_t groundBytes_ = 0;
  double loadMs_ = 0;
};

}  // namespace sv::render
