// The display stage's end of a frame (SPEC §1 stage 5): where each finished tile goes.
#pragma once

#include "core/thread_pool.h"
#include "output/resolve.h"
#include "render/frame_renderer.h"

namespace sv::render {

// Each tile is resolved into the image as soon as it is finished (k divides the 64-pixel tile, so a
// pixel's k×k supersamples always lie in one tile) — or, for the tent filter, which reads across
// tile borders, into a linear frame that is filtered once all tiles are in; the debug views in
// false colour.
class ResolveSink {
 public:
  // `linear` (the tent filter's frame) and `image` are kept by reference for the frame; the image
  // must be sized by output::prepareImage before the first tile. With `linearOut`, every tile is
  // box-resolved into that target and nothing else is done (no filter, no gamma, `linear` and
  // `image` untouched): a caller that composes views in linear light (render/warped.h) takes it
  // from there.
  // With `imageOut` (supersampling 1, no debug view), every tile is box-resolved, blended as it
  // says and put through the table into that rectangle, and nothing else is done.
  ResolveSink(const RenderOptions& options, const output::GammaTable& gamma,
              output::LinearImage& linear, Image& image,
              const output::LinearTarget* linearOut = nullptr,
              const output::ImageTarget* imageOut = nullptr);
  // The sinks finishTile hands out refer to this object: it stays where it is.
  ResolveSink(const ResolveSink&) = delete;
  ResolveSink& operator=(const ResolveSink&) = delete;

  // FrameSettings::finishTile for a raster `tilesX` tiles wide.
  TileSink finishTile(int tilesX);
  // Whether finishTile can take colour sums (FrameSettings::colorSums): both box resolves of
  // anti-aliased samples need only each pixel's sum.
  bool takesColorSums() const;
  // After the frame's tiles: the tent filter, in bands of rows on `pool`. Returns its
  // milliseconds (0 without it).
  double finish(core::ThreadPool& pool);

 private:
  const RenderOptions& options_;
  const output::GammaTable& gamma_;
  output::LinearImage& linear_;
  Image& image_;
  bool linearOut_;
  const output::ImageTarget* imageOut_;
  output::LinearTarget target_;  // where linear tiles go: linearOut's, or the whole of `linear`
};

}  // namespace sv::render
