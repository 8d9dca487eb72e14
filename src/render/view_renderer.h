// One view of a frame, from the scene and a camera to the resolved image (SPEC §1 stages 2–5):
// what a Renderer keeps from frame to frame — its threads, tables and buffers — and the one
// function that wires a view through them (STYLE.md habit 1). Renderer draws the classic view and
// each display channel with it; distortion correction (render/warped.h) each sub-frustum cell.
#pragma once

#include "core/thread_pool.h"
#include "core/timing.h"
#include "output/resolve.h"
#include "render/camera.h"
#include "render/draw_packets.h"
#include "render/frame_renderer.h"
#include "render/passes.h"
#include "render/segment_renderer.h"
#include "render/shading_tables.h"
#include "render/tile_gather.h"
#include "synthvis/frame_stats.h"
#include "synthvis/render.h"
#include "synthvis/tile_share.h"

namespace sv::render {

// The worker threads a renderer runs: `requested`, or for 0 one per hardware thread (at most
// kMaxThreads).
int resolveThreads(int requested);
// The options' transfer function as the resolve's look-up table: sRGB, or the display gamma.
output::GammaTable gammaTableOf(const RenderOptions& options);

class ViewRenderer {
 public:
  explicit ViewRenderer(const RenderOptions& options);  // threads and gamma from `options`

  // One view: the shading tables in the camera's eye space, every instance's vertices to clip
  // space, setup and the tiles with the frame's passes, each tile resolved into `image` as it is
  // finished. `o` is the renderer's options at this view's size; adds to `stats`. With a shared
  // `share`, only its part's tiles are drawn, and part 0's image is assembled from every part's
  // (the other parts' hold their own tiles alone).
  Status render(const scene::Scene& scene, const RenderOptions& o, const FrameCamera& camera,
                Image& image, FrameStats& stats, const TileShare& share = {});
  // The same view box-resolved into linear light (`out`, sized to the view; no filter, no gamma
  // table): for a caller that composes views before the gamma table.
  Status renderLinear(const scene::Scene& scene, const RenderOptions& o, const FrameCamera& camera,
                      output::LinearImage& out, FrameStats& stats);
  // The same into a rectangle of a larger linear image (target.width × target.height must be the
  // view's o.width × o.height): a sub-frustum cell straight into its display's frame.
  Status renderLinear(const scene::Scene& scene, const RenderOptions& o, const FrameCamera& camera,
                      const output::LinearTarget& target, FrameStats& stats);

  // A view whose stages 2–3 a caller made (shading tables in the camera's eye space, and draw
  // packets in its clip space, their materials from those tables): setup, the tiles with the
  // frame's passes and the resolve, into a rectangle of a larger linear image. The sub-frusta
  // stage's cells: each cell's share of the display's packets, through its own map.
  Status renderPacketsLinear(const scene::Scene& scene, const RenderOptions& o,
                             const FrameCamera& camera, const DrawPackets& packets,
                             const ShadingTables& shading, const output::LinearTarget& target,
                             FrameStats& stats);
  // The same resolved through the gamma table (and blended, as the target says) into a rectangle
  // of a larger image: a cell whose display frame is not kept in linear light. Supersampling 1.
  Status renderPacketsImage(const scene::Scene& scene, const RenderOptions& o,
                            const FrameCamera& camera, const DrawPackets& packets,
                            const ShadingTables& shading, const output::ImageTarget& target,
                            FrameStats& stats);

  core::ThreadPool& pool() { return frame_.pool(); }
  const output::GammaTable& gamma() const { return gamma_; }

 private:
  // The segment pipeline's view (RenderOptions::Pipeline::segments) into `image`.
  Status runSegments(const scene::Scene& scene, const RenderOptions& o, const FrameCamera& camera,
                     Image& image, FrameStats& stats);
  Status run(const scene::Scene& scene, const RenderOptions& o, const FrameCamera& camera,
             Image& image, const output::LinearTarget* linearOut, FrameStats& stats,
             const TileShare& share);
  // Stages 3–5 from `packets` (run's, or a caller's).
  Status drawPackets(const scene::Scene& scene, const RenderOptions& o, const FrameCamera& camera,
                     const DrawPackets& packets, const ShadingTables& shading, Image& image,
                     const output::LinearTarget* linearOut, FrameStats& stats,
                     const TileShare& share, core::Clock::time_point start,
                     const output::ImageTarget* imageOut = nullptr);

  FrameRenderer frame_;
  SegmentRenderer segments_;
  output::GammaTable gamma_;
  ShadingTables shading_;
  DrawPackets packets_;
  output::LinearImage linear_;  // the box-resolved frame, for the tent filter
  FramePasses passes_;
  Image unused_;  // the image argument of a linear view's resolve, never written
  ShareBuffers shareBuffers_;  // a shared view's tiles on their way to part 0
};

}  // namespace sv::render
