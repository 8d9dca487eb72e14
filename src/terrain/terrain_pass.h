// Terrain in the frame: a tile pass (raster/tile_pass.h, stage `surfaces`) that ray casts the
// scene's height fields (terrain/caster.h) into each tile's depth and samples, after the opaque
// polygons and the free forms, shading each pixel once where its samples meet the ground.
//
// Based on: SPEC §12 (multi-level ray casting: the screen quadtree from the tile down to 8×8
// windows, each marched in depth from where its parent stopped — front to back, bounded by the
// farthest depth already in the window, so what polygons hide is never cast — then its 4×4
// blocks' rays walked together as packets, packet_walk.h), §5 (one ray per
// sample, the frame's sample pattern: silhouettes and ridges anti-aliased with the polygons'),
// §7 (seed 001's planar texture: the draped image by the map plane's anchor and axes), §8.
#pragma once

#include <memory>
#include <vector>

#include "core/eye_rays.h"
#include "raster/tile_pass.h"
#include "shade/shading.h"
#include "synthvis/height_field.h"
#include "terrain/caster.h"
#include "terrain/ground.h"
#include "terrain/shade_lanes.h"
#include "texture/texture.h"

namespace sv::terrain {

// The colour ramp of a terrain without an image or a ramp of its own: sea-level greens through
// browns and greys to snow, over the table's own height range [lo, hi] (docs/terrain.md).
std::vector<scene::TerrainColorStop> defaultRamp(double lo, double hi);
// The ramp's colour at height `h` (linear between stops, the end stops' beyond them).
Vec3 rampAt(const std::vector<scene::TerrainColorStop>& ramp, double h);

// One terrain as a frame draws it: plain inputs, which the renderer makes from the scene's
// terrains (render/terrains.h).
struct TerrainDraw {
  const HeightField* field = nullptr;  // outlives the frame
  Interpolation interp = Interpolation::bilinear;
  Placement placement;
  shade::MaterialShading material;  // material.texture: the draped image, or null
  float color[3] = {1, 1, 1};       // multiplies the image or the ramp
  const texture::Texture* detail = nullptr;
  double detailSize = 10;
  double imageBounds[4] = {0, 0, 1, 1};       // the image's corners in map metres: W, S, E, N
  std::vector<scene::TerrainColorStop> ramp;  // without an image: never empty
  // A pixel's width per unit eye depth, in grid steps (Caster's levels of detail), or 0 for the
  // table's own surface everywhere.
  double pixel = 0;
};

class TerrainPass final : public raster::TilePass {
 public:
  TerrainPass();
  ~TerrainPass() override;
  // The terrains a frame draws, seen along `rays` (the camera's; prepare sets their raster);
  // `environment` must outlive the frame.
  void setTerrains(std::vector<TerrainDraw> terrains, const EyeRays& rays,
                   const shade::Environment& environment);

  raster::PassStage stage() const override { return raster::PassStage::surfaces; }
  void prepare(const raster::PassFrame& frame) override;
  void drawTile(const raster::TileTarget& tile) override;
  void addStats(FrameStats& stats) const override;

 private:
  struct Drawn : TerrainDraw {
    std::unique_ptr<Caster> caster;
  };
  struct Scratch;
  struct alignas(64) WorkerStats {
    CastCounters counts;
    double ms = 0;  // the worker's time in drawTile this frame
  };

  void drawTerrains(const raster::TileTarget& tile);
  void castWindow(Scratch& w, const Drawn& t, int x0, int y0, int size, double start) const;
  void castBlock(Scratch& w, const Drawn& t, int x0, int y0, double start) const;
  struct Drape;
  struct PixelHit;
  // Where pixel p's first sample met the ground, into `h` (filled in place: 16 a batch).
  void hitOf(const Scratch& w, const Drawn& t, int p, PixelHit& h) const;
  void shadePixel(const Drawn& t, const Drape& drape, const PixelHit& h, int i,
                  shade::Fragments& frag, shade::TexCoords& tc) const;
  ShadeFrame shadeFrame(const Drawn& t, const Drape& drape) const;
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

}  // namespace sv::terrain
