// Whole-frame timing for `synthvis bench` (shared BENCH.md: medians over ≥ 10 frames after ≥ 2
// warm-up frames).
#pragma once

#include <vector>

#include "synthvis/image.h"
#include "synthvis/render.h"
#include "synthvis/scene.h"

namespace sv {

struct FrameTimings {
  std::vector<double> frameMs;  // wall time of each timed frame, render() call to image
  double medianMs = 0, minMs = 0, maxMs = 0;
  double medianRasterMs = 0;  // setup + tiles only (what a GPU's glFinish would cover)
  FrameStats stats;           // of the last frame
  Image image;                // the last frame
};

// Renders `scene` warmup + frames times with one Renderer and times each frame.
Result<FrameTimings> timeFrames(const scene::Scene& scene, const RenderOptions& options, int frames,
                                int warmup);

}  // namespace sv
