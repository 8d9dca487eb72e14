// Distortion correction the seeds' way (SPEC §12; issue 34, method (a)): a display channel drawn
// through a plan of sub-frusta (display/subfrustum.h), each cell a view of its own whose
// projection is the cell's projective map — so the geometry lands pre-distorted on the display's
// own pixels, with no resampling. Every primitive goes through the cell's camera: polygons and
// lines and light points by its matrix, free forms by the projective map of the view volume onto
// the cube (which a cell's projection is), terrain and volumes by the rays of its inverse
// (core/eye_rays.h).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/quadric.h"
#include "core/thread_pool.h"
#include "display/subfrustum.h"
#include "output/resolve.h"
#include "render/camera.h"
#include "render/view_renderer.h"

namespace sv::render {

// The camera of one cell: `base`'s view moved to the display's eye (`eye`, in `base`'s eye frame,
// the origin of the plan's directions), the cell's projection with the camera's depth range, the
// base window kept for what a frame chooses once (levels of detail: every cell chooses as the
// channel would).
FrameCamera cellCamera(const FrameCamera& base, const display::SubFrustumCell& cell, Vec3d eye);

// The cone from the display's eye that holds the directions of a run of a plan's cells
// (render/warped.cpp, the light cull): about the mean of their corners, out to the farthest, and
// the coarsest pixel angle at a cell's centre (what a reach in pixels widens it by).
struct PlanCone {
  Vec3d axis;
  double halfAngle = 0, pixelAngle = 0;
  bool empty = true;            // no fitted cell
  bool everyDirection = false;  // corners all around the eye
};
PlanCone planCone(const display::SubFrustumPlan& plan, size_t c0, size_t c1);

struct SubFrustumStats {
  int cells = 0;               // cells drawn (the plan's fitted ones)
  int64_t unfittedPixels = 0;  // valid pixels of cells without a map: black
  double maxResidualPixels = 0;
};

// Draws a display's cells on a pool's threads, a cell to a worker at a time, each worker with a
// single-threaded view renderer of its own: a cell's raster is a tile or two, too small to share
// among threads, and the cells are many. Kept from frame to frame (the renderers' buffers).
class SubFrustumRenderer {
 public:
  explicit SubFrustumRenderer(const RenderOptions& options);  // the options' threads and gamma

  // Draws the channel seen by `base` through `plan`: every fitted cell at its own size (o.width ×
  // o.height are the plan's; each cell's raster is its rectangle, supersampled and anti-aliased
  // as `o` says) into its rectangle of `out` (linear light, the box resolve — no filter, no
  // gamma). Each display pixel is drawn once, by the one cell that holds it, at its own pixel
  // centre and samples, so abutting cells neither crack nor overlap. Pixels that `valid` (one
  // byte a display pixel, or empty: all) marks invalid, and those of unfitted cells, are black.
  // `stats` gets the cells' counts summed. Identical bytes for any thread count.
  Status render(const scene::Scene& scene, const RenderOptions& o, const FrameCamera& base,
                Vec3d eye, const display::SubFrustumPlan& plan, const std::vector<uint8_t>& valid,
                output::LinearImage& out, FrameStats& stats, SubFrustumStats* cellStats = nullptr);

  const output::GammaTable& gamma() const { return workers_[0]->gamma(); }

 private:
  // cellLights_ for this frame: every light whose splat can reach a cell, for each cell — culled
  // once for all of them, not by each cell's light pass over every light.
  void cullLights(const scene::Scene& scene, const FrameCamera& base, Vec3d eye,
                  const display::SubFrustumPlan& plan);

  core::ThreadPool pool_;
  std::vector<std::unique_ptr<ViewRenderer>> workers_;  // one per pool worker, one thread each
  std::vector<FrameStats> cellStats_;                   // one per cell, this frame
  std::vector<Status> cellErrors_;                      // likewise
  std::vector<std::vector<uint32_t>> cellLights_;       // likewise (cullLights)
  struct LightDirection {
    Vec3d direction;  // unit, from the display's eye
    uint32_t index;   // the light's (LightInput::subset)
  };
  std::vector<LightDirection> lightDirections_;  // this frame's, but for a light at the eye
 public:
  // What depends on the plan alone, made when it changes (a new plan, a moved eye's refit) and
  // known again by its cells: the light cull's cones, per top group and per group of cells, and
  // the pixels no cell holds, as runs of a row.
  struct PlanState {
    int width = 0, height = 0;
    std::vector<display::SubFrustumCell> cells;
    std::vector<PlanCone> top, group;
    struct Group {
      size_t first = 0;   // the group's first fitted cell
      double slack = -1;  // SubFrustumRenderer's light cull: see groupOf in warped.cpp
    };
    std::vector<Group> groups;
    struct Run {
      int y, x0, x1;
    };
    std::vector<Run> uncovered;
  };

 private:
  void preparePlan(const display::SubFrustumPlan& plan);
  PlanState plan_;
};

}  // namespace sv::render
