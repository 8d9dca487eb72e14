#include "render/resolve_sink.h"

#include <algorithm>

#include "core/check.h"
#include "core/timing.h"

namespace sv::render {

ResolveSink::ResolveSink(const RenderOptions& options, const output::GammaTable& gamma,
                         output::LinearImage& linear, Image& image,
                         const output::LinearTarget* linearOut, const output::ImageTarget* imageOut)
    : options_(options),
      gamma_(gamma),
      linear_(linear),
      image_(image),
      linearOut_(linearOut != nullptr),
      imageOut_(imageOut) {
  SV_CHECK(!imageOut || (!linearOut && options.supersample == 1 &&
                         options.debugView == RenderOptions::DebugView::none));
  if (imageOut) {
  } else if (linearOut) {
    target_ = *linearOut;
  } else if (options.filter == RenderOptions::Filter::tent3) {
    linear.resize(options.width, options.height);
    target_ = output::wholeOf(linear);
  }
}

bool ResolveSink::takesColorSums() const {
  return options_.debugView == RenderOptions::DebugView::none && options_.supersample == 1;
}

TileSink ResolveSink::finishTile(int tilesX) {
  const RenderOptions& o = options_;
  const int k = o.supersample;
  if (imageOut_)
    return [this, tilesX](int tile, const float*, const uint16_t* color, const int32_t* sums) {
      output::resolveSampleTileTo(color, sums, tile % tilesX, tile / tilesX, options_.samples,
                                  gamma_, *imageOut_);
    };
  if (o.debugView != RenderOptions::DebugView::none && !linearOut_) {
    const output::DebugPalette palette = o.debugView == RenderOptions::DebugView::overdraw
                                             ? output::DebugPalette::count
                                             : output::DebugPalette::level;
    return [this, tilesX, palette](int tile, const float*, const uint16_t* color, const int32_t*) {
      output::resolveDebugTile(color, tile % tilesX, tile / tilesX, palette, image_);
    };
  }
  if (linearOut_ || o.filter == RenderOptions::Filter::tent3)
    return [this, tilesX, k](int tile, const float*, const uint16_t* color, const int32_t* sums) {
      output::resolveTileLinear(color, sums, tile % tilesX, tile / tilesX, k, options_.samples,
                                target_);
    };
  if (o.samples > 1)
    return [this, tilesX](int tile, const float*, const uint16_t* color, const int32_t* sums) {
      output::resolveSampleTile(color, sums, tile % tilesX, tile / tilesX, options_.samples, gamma_,
                                image_);
    };
  return [this, tilesX, k](int tile, const float*, const uint16_t* color, const int32_t*) {
    output::resolveTile(color, tile % tilesX, tile / tilesX, k, gamma_, image_);
  };
}

double ResolveSink::finish(core::ThreadPool& pool) {
  if (linearOut_ || imageOut_ || options_.filter != RenderOptions::Filter::tent3) return 0;
  const auto t0 = core::Clock::now();
  constexpr int kBand = 16;  // rows per task
  const int height = options_.height;
  pool.parallelFor(size_t((height + kBand - 1) / kBand), [&](size_t band, int) {
    const int y0 = int(band) * kBand;
    output::tentFilterRows(linear_, gamma_, y0, std::min(height, y0 + kBand), image_);
  });
  return core::msSince(t0);
}

}  // namespace sv::render
