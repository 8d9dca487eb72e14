#include "render/frame_settings.h"

#include <fmt/format.h>

#include <algorithm>

namespace sv::render {
namespace {

// With anti-aliasing, a frame of several batches keeps a whole-frame sample buffer (samples × 10
// bytes a pixel: 330 MB at 1080p with 16 samples). Batches as large as the records that buffer
// would hold (144 bytes a triangle) cost no more memory and avoid it for all but huge scenes;
// beyond that the buffer is allowed up to 4 GiB.
Status sizeBatches(const RenderOptions& o, size_t triangles, FrameSettings& fs) {
  const size_t tiles = size_t((fs.width + raster::kTileSize - 1) >> raster::kTileLog2) *
                       size_t((fs.height + raster::kTileSize - 1) >> raster::kTileLog2);
  const size_t bufferBytes = tiles * raster::kTilePixels * size_t(o.samples) *
                             (sizeof(float) + raster::kColorChannels * sizeof(uint16_t));
  const size_t batch = std::clamp<size_t>(bufferBytes / sizeof(geometry::TriangleSetup),
                                          fs.batchTriangles, kMaxBatchTriangles);
  fs.batchTriangles = uint32_t(batch);
  if (triangles > batch && bufferBytes > (size_t(4) << 30))
    return Error{"", "",
                 fmt::format("{} triangles in a {}x{} frame with {} samples per pixel need a "
                             "{:.1f} GB sample buffer (over the 4 GB limit); use fewer samples",
                             triangles, o.width, o.height, o.samples, double(bufferBytes) / 1e9)};
  return {};
}

}  // namespace

Result<FrameSettings> makeFrameSettings(const RenderOptions& o, Vec3 background,
                                        const shade::Environment& environment, bool pixelShading,
                                        size_t triangles) {
  using DebugView = RenderOptions::DebugView;
  FrameSettings fs;
  fs.width = o.width * o.supersample;
  fs.height = o.height * o.supersample;
  fs.clearColor[0] = background.x;
  fs.clearColor[1] = background.y;
  fs.clearColor[2] = background.z;
  fs.shade = o.debugView == DebugView::overdraw ? raster::ShadeMode::overdraw
             : o.debugView == DebugView::levels ? raster::ShadeMode::levels
             : pixelShading                     ? raster::ShadeMode::material
                                                : raster::ShadeMode::gouraud;
  fs.environment = &environment;
  fs.samples = o.samples;
  fs.debugOccupancy = o.debugView == DebugView::occupancy;
  fs.masking = o.debugView == DebugView::overdraw      ? raster::Masking::none
               : o.hsr == RenderOptions::Hsr::priority ? raster::Masking::priority
               : o.hsr == RenderOptions::Hsr::hybrid   ? raster::Masking::hybrid
                                                       : raster::Masking::none;
  if (o.samples > 1)
    if (Status s = sizeBatches(o, triangles, fs); !s) return s.error();
  return fs;
}

}  // namespace sv::render
