// Free forms in the frame: a tile pass (raster/tile_pass.h, stage `surfaces`) that ray casts them
// per 64×64 tile into the tile's own depth and colour buffers (raster/framebuffer.h), after the
// tile's opaque polygons and before its translucent ones, so that free forms and polygons meet at
// exact, anti-aliased intersection curves (issue 7 item 4).
//
// Based on: SPEC §12 (multi-level ray casting; at a leaf the surface point, the normal from the
// gradient, Phong shading, fog, depth), §5 (the same sample pattern as the polygons: one ray per
// sample, colour shaded once per pixel and object), §8 (shading, through shade::shadeFragments).
#pragma once

#include <cstdint>
#include <vector>

#include "freeform/raycast.h"
#include "freeform/surface_points.h"
#include "raster/tile_pass.h"
#include "shade/shading.h"

namespace sv::freeform {

// One free-form object as the pass draws it.
struct ShadedForm {
  FreeForm form;                // object space: the gradient gives the normal
  ProjectedFreeForm projected;  // in the cube: what is cast
  Mat4d objectToEye;            // for the eye-space position (fog, point lights, specular)
  Mat4d normalToEye;            // the inverse transpose of objectToEye's 3×3 part
  shade::MaterialShading material;
  float color[3] = {1, 1, 1};  // linear base colour
  // material.texture: projected along the object's y axis, u = x·uvScale[0], v = z·uvScale[1]
  // (object space), its level of detail from the pixel's footprint on the tangent plane.
  float uvScale[2] = {1, 1};
};

// The frame's free forms, which tiles each may show in (so a tile casts only those), and their
// cast into each tile.
class FreeFormPass final : public raster::TilePass {
 public:
  // The frame's forms and how to draw them; call before prepare. `environment` (lights, fog) must
  // outlive the frame. marchSteps > 0: the fixed-step marcher instead of the caster (the
  // baseline).
  void setForms(std::vector<ShadedForm> forms, const shade::Environment* environment,
                const CastSettings& settings, int marchSteps);

  raster::PassStage stage() const override { return raster::PassStage::surfaces; }
  // Finds, for every form, the tiles of the raster whose pixel squares its surface may cross, by
  // the same bounds the caster uses, windows of the screen subdivided from the whole raster down
  // to tiles — the forms shared among the pool's threads, the result the same.
  void prepare(const raster::PassFrame& frame) override;
  // Casts the forms listed for the tile into its buffers, shading each pixel once per form that
  // takes any of its samples.
  void drawTile(const raster::TileTarget& tile) override;
  // freeForms, and the cells, masked cells, bounds, rays and hits of every worker's casts.
  void addStats(FrameStats& stats) const override;

 private:
  // Per-thread buffers: the tile's samples row by row while it is cast.
  struct Scratch {
    std::vector<float> depth;
    std::vector<uint32_t> object;
    std::vector<double> cubeZ;
    std::vector<float> centreDepth;  // CastSettings::adaptiveSamples: the pixel centres' cast
    std::vector<uint32_t> centreObject;
    std::vector<double> centreZ;
    std::vector<uint32_t> ringObject;  // the centres with a one-pixel ring around the tile
    std::vector<float> ringDepth;
    std::vector<uint8_t> pixelState;    // per pixel: what its samples take (castAdaptive)
    std::vector<float> bandLo, bandHi;  // per pixel: its form's depth band
    RayFunction ray;
    struct Pending {  // a pixel to shade, and its first sample the form took
      int lx, ly, sample;
    };
    std::vector<std::vector<Pending>> pending;  // per listed form
    std::vector<std::vector<int>> wholeBlocks;  // per listed form: the blocks it took whole
    std::vector<uint32_t> place;                // per form: its place in the tile's list
    std::vector<int> lastPixel;                 // per listed form: the last pixel pending
    SurfaceLanes surface;
    // shadeBatch's fragments' cube points.
    alignas(64) double cubeX[shade::kMaxFragments] = {}, cubeY[shade::kMaxFragments] = {},
                       cubeZPoint[shade::kMaxFragments] = {};
    std::vector<double> columnX, rowY;  // per sample: the tile's columns' cube x, rows' cube y
    std::vector<uint64_t> active;       // per listed form: its perturbations that may be positive
    std::vector<uint64_t>
        pixelActive;  // per sample plane and pixel: its hit's (CastWindow::active)
  };
  // Per worker, a cache line each: workers count into theirs while casting, and two workers'
  // counters in one line would make each write wait for the other core (false sharing).
  struct alignas(64) WorkerStats {
    CastStats counts;
  };
  // One tile's cast, as drawTile hands it from step to step.
  struct TileJob;

  // A tile form `form` may show in, with the nearest cube depth its bounds allow there.
  struct Mark {
    uint32_t tile;
    double nearest;
  };
  void markTiles(uint32_t form, int x0, int y0, int size, double zlo, double zhi,
                 std::vector<Mark>& marks) const;
  void sortTileLists();

  // drawTile's steps.
  void readDepths(TileJob& job) const;
  void castTile(TileJob& job, float* depth, uint32_t* object, double* cubeZ, uint64_t* active,
                double dx, double dy) const;
  void castEverySample(TileJob& job) const;
  void castAdaptive(TileJob& job) const;
  void castCentresWithRing(TileJob& job) const;
  void classifyPixels(TileJob& job) const;
  void castSampleRays(TileJob& job) const;
  void listPixels(TileJob& job) const;
  void shadeForm(TileJob& job, size_t place) const;
  void shadeBatch(TileJob& job, size_t place, shade::Fragments& frag, const Scratch::Pending* batch,
                  int count, int block) const;
  void writeBack(TileJob& job, uint32_t form, const Scratch::Pending* batch, int first, int n,
                 int block, const float (*out)[shade::kMaxFragments]) const;

  std::vector<ShadedForm> forms_;
  std::vector<SurfacePoints> surfaces_;  // per form: its hits' points and normals
  int width_ = 0, height_ = 0, samples_ = 1, tilesX_ = 0, tilesY_ = 0;
  double offsetX_[64] = {}, offsetY_[64] = {};  // sample offsets from the pixel centre, pixels
  const shade::Environment* environment_ = nullptr;
  CastSettings settings_;
  int marchSteps_ = 0;  // > 0: the fixed-step marcher instead of the caster (the baseline)
  // Per tile, the forms it casts, nearest first (by the nearest depth their bounds allow in the
  // tile), so that masking drops what nearer forms hide.
  std::vector<std::vector<uint32_t>> tileForms_;
  // The nearest cube depth each listed form's bounds allow in the tile, in the same order.
  std::vector<std::vector<double>> tileNearest_;
  std::vector<std::vector<Mark>> marks_;  // per form (prepare's)
  std::vector<Scratch> scratch_;          // per worker
  std::vector<WorkerStats> stats_;        // per worker
};

}  // namespace sv::freeform
