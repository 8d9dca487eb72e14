// One projector's frame of a curved-screen display (issue 34): the scene pre-distorted for the
// projector's pixels, by method (a) — the seeds' sub-frusta, each cell drawn through its own
// projective map (render/warped.h, no resampling) — or method (b), the industry's — a flat view
// with a margin rendered and resampled through the display mapping (display/resample.h) — then
// edge-blended, all in linear light before the gamma table.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "display/blend.h"
#include "display/mpcdi.h"
#include "display/resample.h"
#include "display/subfrustum.h"
#include "display/viewer.h"
#include "render/warped.h"
#include "synthvis/display.h"

namespace sv::render {

// What a display's frames are drawn with, kept from frame to frame: the cells' renderers (method
// (a)) and a view renderer for the flat view (method (b)), each made on first use with the
// options' threads; the gamma table; threads for the work on whole display frames (resampling,
// the gamma table).
class CorrectionRenderer {
 public:
  explicit CorrectionRenderer(const RenderOptions& options);
  SubFrustumRenderer& cells();
  ViewRenderer& flat();
  output::LinearImage& flatImage() { return flatImage_; }  // (b): the flat view's
  const output::GammaTable& gamma() const { return gamma_; }
  core::ThreadPool& pool() { return pool_; }

  // A projector's frame from linear light to `image`: the tent filter when `o` asks for it, else
  // the gamma table alone, in bands of rows on the threads.
  void encode(const output::LinearImage& linear, const RenderOptions& o, Image& image);

 private:
  RenderOptions options_;
  output::GammaTable gamma_;
  core::ThreadPool pool_;
  std::optional<SubFrustumRenderer> cells_;
  std::optional<ViewRenderer> flat_;
  output::LinearImage flatImage_;
};

// A projector's display mapping and how it is corrected. `plan` (method (a)) and `warp` (method
// (b)) are made from `table` when not given: both depend on the mapping alone, so a caller
// drawing frame after frame makes them once (and again when the mapping changes).
struct CorrectedView {
  const display::DirectionTable* table = nullptr;
  const display::SubFrustumPlan* plan = nullptr;
  const display::ResampleWarp* warp = nullptr;
  const display::BlendWeights* blend = nullptr;  // nothing: no edge blending
  Vec3d eye{0, 0, 0};                            // the display's eye in the camera's eye frame
  RenderOptions::Correction correction = RenderOptions::Correction::subFrusta;
  int marginPixels = 2;  // (b): the flat view's margin, when the warp is made here
};

// Method (b)'s warp for a display mapping: the flat view that covers every direction with a
// margin of `marginPixels`, looking along their mean, at the display's finest angular pixel
// (display::coveringFlatView), and where each display pixel lands in it.
Result<display::ResampleWarp> resampleWarpOf(const display::DirectionTable& table,
                                             int marginPixels = 2);

// The projector's frame in linear light (`out`, the table's size; o.width and o.height are not
// used), for the scene seen from `base`'s eyepoint; with `image`, through the gamma table too
// (CorrectionRenderer::encode) — for sub-frusta and the box filter, each cell blended and encoded
// as it is finished (SubFrustumRenderer::Finish), with no pass over the frame after; without
// `keepLinear`, `out` is then not written at all (the cells resolve straight into `image`).
Status renderCorrected(CorrectionRenderer& renderer, const scene::Scene& scene,
                       const RenderOptions& o, const FrameCamera& base, const CorrectedView& view,
                       output::LinearImage& out, FrameStats& stats, DisplayStats& cs,
                       Image* image = nullptr, bool keepLinear = true);

// A display of projectors: each one's name, display mapping and blend weights — the demo rig's
// (analytic) or an MPCDI file's — and the rig's geometry when it is known (for the viewer).
// A projector's sub-frustum plan, made the first time a frame needs it and then kept: a display's
// tables never change (synthvis/display.h holds its setup const), and a plan takes 141 ms at
// 1920×1080 (issue 61). Made again only for another depth range. A copy starts empty (a copied
// setup's table may be changed).
class PlanCache {
 public:
  PlanCache() = default;
  PlanCache(const PlanCache&) {}
  PlanCache& operator=(const PlanCache&) {
    std::lock_guard lock(mutex_);
    plan_.reset();
    points_.reset();
    movedPlan_.reset();
    return *this;
  }
  // The plan of `table` under `options`: kept, or made now (`madeMs` then its time, else 0).
  std::shared_ptr<const display::SubFrustumPlan> of(const display::DirectionTable& table,
                                                    const display::SubFrustumOptions& options,
                                                    double& madeMs) const;
  // Dynamic correction (issue 61): the plan for the eye of `moved` — `design` (the geometry
  // `table` was made from) with its eye moved — refitted from the design plan (display::refitPlan,
  // the design plan's screen points kept with it), and kept until the eye moves again. The design
  // eye's own is `of`'s. `refitMs` gets the refit's time (0 when the eye has not moved since the
  // last call), `stats` its counts.
  std::shared_ptr<const display::SubFrustumPlan> moved(
      const display::DirectionTable& table, const display::SubFrustumOptions& options,
      const display::DisplayGeometry& design, const display::DisplayGeometry& moved,
      core::ThreadPool* pool, double& madeMs, double& refitMs, display::RefitStats& stats) const;

 private:
  mutable std::mutex mutex_;
  mutable std::shared_ptr<const display::SubFrustumPlan> plan_;
  mutable display::SubFrustumOptions options_;
  mutable std::optional<display::PlanScreenPoints> points_;           // plan_'s, for a moved eye
  mutable std::shared_ptr<const display::SubFrustumPlan> movedPlan_;  // for movedEye_
  mutable Vec3 movedEye_{0, 0, 0};
  mutable display::RefitStats movedStats_;
};

struct ProjectorSetup {
  std::string name;
  display::DirectionTable table;
  PlanCache plan;                          // method (a)'s plan of `table`
  std::optional<display::BlendMap> alpha;  // the alpha map `blend` comes from, when known
  std::optional<display::BlendWeights> blend;
  std::optional<display::MpcdiRegion> region;  // an MPCDI file's region it was read from
};
struct DisplaySetup {
  std::vector<ProjectorSetup> projectors;
  std::optional<display::CylinderRig> rig;
  Vec3d eye{0, 0, 0};  // the display's eye in the camera's eye frame
};
// Issue 34's demo: display::threeProjectorCylinder with projectors of width × height and
// `overlapDegrees` of overlap, the exact directions (in double) and the rig's alpha maps
// (display::cylinderAlphaMaps, 16-bit at half the projectors' resolution).
DisplaySetup cylinderDisplay(int width, int height, double overlapDegrees = 10);
// An MPCDI file's regions (3d profile: each region's frustum and warp give its directions; its
// alpha and beta maps its blend), named by their ids.
Result<DisplaySetup> mpcdiDisplay(const std::string& path);
// The display at 1/r of its projectors' resolution — each ⌈w/r⌉ × ⌈h/r⌉, the same screen, lenses
// and blend maps (a rig's projectors resized, an MPCDI region's resolution divided: its warp and
// alpha maps are sampled at the new pixel centres) — what an image generator draws at a
// half-resolution quality level and shows each pixel r × r times.
DisplaySetup scaledDisplay(const DisplaySetup& display, int r);

// The rig of a cylinderDisplay as an MPCDI file (3d profile, level 2): a buffer with a region per
// projector, its frustum the projector's covering flat view, a per-pixel warp, its alpha map.
Result<display::Mpcdi> mpcdiOf(const DisplaySetup& display);

// Every projector's frame of the display (renderCorrected), in linear light and through the
// gamma table (the tent filter's too, when `o` asks for it).
struct DisplayFrame {
  std::vector<output::LinearImage> linear;
  std::vector<Image> images;
  std::vector<FrameStats> stats;
  std::vector<DisplayStats> correction;
};
// What one call draws: the eye moved from the design eye (head tracking, or a design eye the
// host moves: display::refitPlan for a rig, whose screen is known; a display read from a file
// keeps its design eye's correction and moves the viewpoint alone), and which projectors (the
// others' frames are left as they were).
struct DisplayRequest {
  Vec3d eyeOffset{0, 0, 0};  // metres, in the camera's eye frame (x right, y up, z back)
  const std::vector<int>* projectors = nullptr;  // nullptr: every one
  bool keepLinear = true;                        // DisplayFrame::linear written (for the viewer)
};
Status renderDisplay(CorrectionRenderer& renderer, const scene::Scene& scene,
                     const RenderOptions& o, const DisplaySetup& display, DisplayFrame& frame,
                     const DisplayRequest& request = {});

// Pictures in the viewer's frame shown on the display (an image generator's test patterns and
// overlay, docs/display.md "Pictures on the screen"): a panorama around the display's eye
// (display::panoramaOf its projectors' directions) that each projector pixel samples in its own
// direction, so that the picture comes out undistorted and continuous across the projectors.
// Pixels of `pixelDegrees`, coarser where that would make a side over kMaxRasterSize.
display::PanoramaView displayPanorama(const DisplaySetup& display, double pixelDegrees);
// `picture` (codes as `gamma` encodes them, the panorama's size) on every projector: bilinear in
// linear light, blended, through `gamma`; invalid pixels black. In bands of rows on `pool`.
void showPanorama(const DisplaySetup& display, const display::PanoramaView& view,
                  const Image& picture, const output::GammaTable& gamma, core::ThreadPool& pool,
                  std::vector<Image>& images);
// A small picture over the projectors' encoded frames, at (x0, y0) of the panorama: the pixels
// whose directions fall in its rectangle, found once a display (PanoramaPatch), and each frame
// their value v made v·scale + add — the picture given as what it makes of black (`add`) and of
// white (`add + 255·scale`), so that a translucent box and its text keep their look (nearest
// sample).
struct PanoramaPatch {
  int x0 = 0, y0 = 0, width = 0, height = 0;
  struct Pixel {
    uint32_t pixel;  // in the projector's frame
    uint32_t at;     // in the picture
  };
  std::vector<std::vector<Pixel>> pixels;  // per projector
};
PanoramaPatch panoramaPatch(const DisplaySetup& display, const display::PanoramaView& view, int x0,
                            int y0, int width, int height);
void overlayPatch(const PanoramaPatch& patch, const Image& onBlack, const Image& onWhite,
                  std::vector<Image>& images);
// The simulated viewer's view of a rendered display (display::viewerPanorama over the rig's
// screen, from its eye), through the gamma table. Fails for a display without a known rig.
Result<Image> viewerImage(const DisplaySetup& display, const DisplayFrame& frame,
                          const display::PanoramaView& view, const output::GammaTable& gamma);

// The same from a display's encoded frames (what an image generator presented, 8-bit codes as
// `gamma` encodes them: each code taken back to the middle of the linear values it stands for).
Result<Image> viewerImage(const DisplaySetup& display, const std::vector<Image>& frames,
                          const display::PanoramaView& view, const output::GammaTable& gamma);

// The table's directions as floats (a display::DirectionMap: what method (b) resamples through).
display::DirectionMap directionMapOf(const display::DirectionTable& table);

}  // namespace sv::render
