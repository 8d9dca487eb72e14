// Distortion correction the seeds' way (SPEC §12; issue 34, method (a)): a display channel drawn
// through a plan of sub-frusta (display/subfrustum.h), each cell a view of its own whose
// projection is the cell's projective map — so the geometry lands pre-distorted on the display's
// own pixels, with no resampling. Every primitive goes through the cell's camera: polygons and
// lines and light points by its matrix, free forms by the projective map of the view volume onto
// the cube (which a cell's projection is), terrain and volumes by the rays of its inverse
// (core/eye_rays.h).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/quadric.h"
#include "core/thread_pool.h"
#include "display/blend.h"
#include "display/subfrustum.h"
#include "lights/light_laws.h"
#include "output/resolve.h"
#include "render/camera.h"
#include "render/draw_packets.h"
#include "render/shading_tables.h"
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
  //
  // With `finish`, each cell's rectangle is then, while it is in cache, blended (finish->blend, in
  // `out` too) and put through the gamma table into finish->image (sized here): the display's
  // frame with no pass over it after the cells (issue 61: "resolved through the ordinary tile
  // path, gamma inline").
  // Without `linear`, the cells drawn as a stage resolve through the table straight into the
  // image (blend inline; no supersampling) and `out` is left as it was: the frame is not kept in
  // linear light.
  struct Finish {
    const display::BlendWeights* blend = nullptr;  // the display's size, or none
    const output::GammaTable* gamma = nullptr;
    Image* image = nullptr;
    bool linear = true;
  };
  Status render(const scene::Scene& scene, const RenderOptions& o, const FrameCamera& base,
                Vec3d eye, const display::SubFrustumPlan& plan, const std::vector<uint8_t>& valid,
                output::LinearImage& out, FrameStats& stats, SubFrustumStats* cellStats = nullptr,
                const Finish* finish = nullptr);

  const output::GammaTable& gamma() const { return workers_[0]->gamma(); }
  // Whether the cells are drawn as a stage of one frame (the default) or each as a view of its
  // own (issue 34's way, kept to compare against: tests, bench).
  void useStage(bool on) { useStage_ = on; }

 private:
  // cellLights_ for this frame: every light whose splat can reach a cell, for each cell — culled
  // once for all of them, not by each cell's light pass over every light.
  void cullLights(const scene::Scene& scene, const FrameCamera& base, Vec3d eye,
                  const display::SubFrustumPlan& plan);
  // lightDirections_ for this frame; how far a splat reaches from its centre, pixels.
  void lightDirections(const scene::Scene& scene, const FrameCamera& base, Vec3d eye);
  static double lightReach(const scene::Scene& scene);

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
  lights::LightLaws laws_;                       // this frame's, at the display's eye
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

  // The sub-frusta as a stage (issue 61, subfrustum_stage.cpp): the display's traversal, shading
  // tables and vertex stage once a frame, in the clip space of a flat "cover" view that holds
  // every cell; each triangle binned to the cells whose rectangles its box meets; each cell's
  // triangles taken to its own clip space by one 4 × 4 map (its projection after the cover's
  // inverse) and drawn through its own raster. What depends on the plan and the depth range:
  static constexpr int kBins = 32;  // a side of the grid of bins over the cover's NDC
  struct Stage {
    bool ok = false;  // a cover exists (every cell within 84° of their mean direction)
    double znear = 0, zfar = 0;
    Mat4 cover;                // the cover's projection (eye frame from the display's eye → clip)
    std::vector<Mat4> toCell;  // per cell: its projection · the cover's inverse
    // Per cell: its rectangle widened by two pixels, as a box of the cover's NDC (x0, y0, x1, y1).
    std::vector<std::array<float, 4>> box;
    float grid[4] = {-1, -1, 1, 1};  // the bins' domain: the union of the boxes
    // The bins a box of the cover's NDC lies in (x0, y0, x1, y1, inclusive; clamped to the grid).
    std::array<int16_t, 4> bins(const std::array<float, 4>& b) const;
  };
  Stage stage_;
  bool useStage_ = true;
  // This frame's: the shading tables and packets in the cover's clip space; each triangle's NDC box
  // and range of bins (empty for one in no bin); the triangles every cell tries (a vertex at or
  // behind the eye plane); the bins' triangles (CSR: binStart, binTriangles).
  ShadingTables shading_;
  DrawPackets cover_;
  std::vector<std::array<float, 4>> triangleBox_;
  std::vector<std::array<int16_t, 4>> triangleBins_;
  std::vector<uint32_t> binStart_, binTriangles_, everywhere_;
  struct CellScratch {
    DrawPackets packets;
    std::vector<uint32_t> triangles, stamp, remap;
    uint32_t generation = 0;
  };
  std::vector<CellScratch> cellScratch_;  // per worker
  // The lights on the cover too: each light's place there binned on the same grid, and a cell's
  // lights those of its bins within its box widened by the splats' reach (lightBox, made when the
  // reach changes), then tried exactly as cullLights tries them.
  std::vector<std::array<float, 4>> lightBox_;
  double lightReach_ = -1;
  std::vector<std::array<float, 2>> lightPlace_;  // per lightDirections_ entry
  std::vector<uint32_t> lightBinStart_, lightBinLights_;
  void binLights(const scene::Scene& scene, const FrameCamera& base, Vec3d eye,
                 const display::SubFrustumPlan& plan);
  void cellLightsOf(size_t i, const display::SubFrustumPlan& plan);
  void prepareStage(const display::SubFrustumPlan& plan, double znear, double zfar);
  // This frame's stages 2–3 in the cover's clip space, and its triangles binned.
  Status drawCover(const scene::Scene& scene, const RenderOptions& o, const FrameCamera& base,
                   Vec3d eye, FrameStats& stats);
  void binTriangles();
  // Cell i's triangles of cover_, in draw order, taken to its clip space (scratch.packets).
  void cellPackets(size_t i, CellScratch& scratch);
};

}  // namespace sv::render
