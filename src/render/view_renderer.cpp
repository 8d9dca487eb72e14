#include "render/view_renderer.h"

#include <fmt/format.h>

#include <algorithm>
#include <thread>

#include "core/check.h"
#include "core/timing.h"
#include "render/frame_settings.h"
#include "render/resolve_sink.h"
#include "render/tile_gather.h"

namespace sv::render {

int resolveThreads(int requested) {
  if (requested > 0) return requested;
  return std::clamp(int(std::thread::hardware_concurrency()), 1, kMaxThreads);
}

output::GammaTable gammaTableOf(const RenderOptions& o) {
  return o.gamma == 0 ? output::GammaTable::srgb() : output::GammaTable::power(o.gamma);
}

ViewRenderer::ViewRenderer(const RenderOptions& o)
    : frame_(resolveThreads(o.threads)), gamma_(gammaTableOf(o)) {}

Status ViewRenderer::render(const scene::Scene& scene, const RenderOptions& o,
                            const FrameCamera& camera, Image& image, FrameStats& stats,
                            const TileShare& share) {
  return run(scene, o, camera, image, nullptr, stats, share);
}

Status ViewRenderer::renderLinear(const scene::Scene& scene, const RenderOptions& o,
                                  const FrameCamera& camera, output::LinearImage& out,
                                  FrameStats& stats) {
  out.resize(o.width, o.height);
  const output::LinearTarget target = output::wholeOf(out);
  return run(scene, o, camera, unused_, &target, stats, {});
}

namespace {

// A target rectangle of the view's size, inside its image.
template <class Target>
bool fits(const Target& t, const RenderOptions& o) {
  return t.width == o.width && t.height == o.height && t.x >= 0 && t.y >= 0 &&
         t.x + t.width <= t.image->width && t.y + t.height <= t.image->height;
}

}  // namespace

Status ViewRenderer::renderLinear(const scene::Scene& scene, const RenderOptions& o,
                                  const FrameCamera& camera, const output::LinearTarget& target,
                                  FrameStats& stats) {
  SV_CHECK(fits(target, o));
  return run(scene, o, camera, unused_, &target, stats, {});
}

Status ViewRenderer::run(const scene::Scene& scene, const RenderOptions& o,
                         const FrameCamera& camera, Image& image,
                         const output::LinearTarget* linearOut, FrameStats& stats,
                         const TileShare& share) {
  const auto start = core::Clock::now();
  SV_CHECK(!share.shared() || (!linearOut && share.exchange && share.part >= 0 &&
                               share.part < share.parts));
  if (o.pipeline == RenderOptions::Pipeline::segments) {
    if (share.shared())
      return Error{"", "", "the segment pipeline draws a channel in one process, not shared"};
    if (linearOut)
      return Error{"", "", "the segment pipeline draws images, not views in linear light"};
    if (Status s = runSegments(scene, o, camera, image, stats); !s) return s;
    stats.totalMs = core::msSince(start);
    return {};
  }
  // Stage 2: the shading stage's tables in the camera's eye space.
  buildShading(scene, o, camera.view, shading_);
  const bool pixelShading = shading_.any && o.debugView == RenderOptions::DebugView::none;

  // Stage 3: every instance's vertices to clip space, in draw order.
  const auto t0 = core::Clock::now();
  if (Status s = buildDrawPackets(scene, o, camera, pixelShading ? &shading_ : nullptr,
                                  frame_.pool(), packets_);
      !s)
    return s;
  stats.vertexMs = core::msSince(t0);
  return drawPackets(scene, o, camera, packets_, shading_, image, linearOut, stats, share, start);
}

Status ViewRenderer::renderPacketsLinear(const scene::Scene& scene, const RenderOptions& o,
                                         const FrameCamera& camera, const DrawPackets& packets,
                                         const ShadingTables& shading,
                                         const output::LinearTarget& target, FrameStats& stats) {
  SV_CHECK(fits(target, o));
  return drawPackets(scene, o, camera, packets, shading, unused_, &target, stats, {},
                     core::Clock::now());
}

Status ViewRenderer::renderPacketsImage(const scene::Scene& scene, const RenderOptions& o,
                                        const FrameCamera& camera, const DrawPackets& packets,
                                        const ShadingTables& shading,
                                        const output::ImageTarget& target, FrameStats& stats) {
  SV_CHECK(fits(target, o) && o.supersample == 1);
  return drawPackets(scene, o, camera, packets, shading, unused_, nullptr, stats, {},
                     core::Clock::now(), &target);
}

Status ViewRenderer::drawPackets(const scene::Scene& scene, const RenderOptions& o,
                                 const FrameCamera& camera, const DrawPackets& packets,
                                 const ShadingTables& shading, Image& image,
                                 const output::LinearTarget* linearOut, FrameStats& stats,
                                 const TileShare& share, core::Clock::time_point start,
                                 const output::ImageTarget* imageOut) {
  const bool pixelShading = shading.any && o.debugView == RenderOptions::DebugView::none;
  // Stages 3–5: setup and the tiles, with the frame's passes, each tile resolved when finished.
  Result<FrameSettings> settings = makeFrameSettings(o, scene.background, shading.environment,
                                                     pixelShading, packets.indices.size() / 3);
  if (!settings.ok()) return settings.error();
  FrameSettings& fs = settings.value();
  ResolveSink sink(o, gamma_, linear_, image, linearOut, imageOut);
  fs.finishTile = sink.finishTile((fs.width + raster::kTileSize - 1) >> raster::kTileLog2);
  fs.depthToSink = false;  // the resolve reads colour alone
  fs.colorSums = sink.takesColorSums();
  fs.passes = passes_.compose(scene, o, camera, shading);
  fs.share = share;
  if (!linearOut && !imageOut) output::prepareImage(o.width, o.height, image);
  if (Status s = frame_.render(packets, fs, stats); !s) return s;
  if (share.shared()) {
    // Part 0 assembles the image: the finished pixels, or for the tent filter, which reads
    // across tile borders, the box-resolved linear ones it then filters.
    const bool tent = o.filter == RenderOptions::Filter::tent3;
    const SharedPixels pixels{
        tent ? reinterpret_cast<uint8_t*>(linear_.rgb.data()) : image.rgb.data(), o.width,
        o.height, tent ? int(3 * sizeof(uint16_t)) : 3, raster::kTileSize / o.supersample};
    if (Status s = gatherShare(pixels, share, shareBuffers_, stats); !s) return s;
    if (share.part != 0) {
      stats.totalMs = core::msSince(start);
      return {};
    }
  }
  stats.rasterMs += sink.finish(frame_.pool());
  stats.totalMs = core::msSince(start);
  return {};
}

Status ViewRenderer::runSegments(const scene::Scene& scene, const RenderOptions& o,
                                 const FrameCamera& camera, Image& image, FrameStats& stats) {
  // What the segment pipeline does not draw yet (issue 35) is refused, not dropped.
  const char* missing = !scene.freeForms.empty()                                   ? "free forms"
                        : !scene.terrains.empty()                                  ? "terrain"
                        : !scene.volumes.empty()                                   ? "volumes"
                        : !scene.lines.empty()                                     ? "lines"
                        : !scene.lightPoints.empty() || !scene.stars.stars.empty() ? "light points"
                                                                                   : nullptr;
  if (missing)
    return Error{
        "", "",
        fmt::format("the segment pipeline draws polygons only so far: the scene has {}", missing)};
  // Vertex colours, and fog along the run; not the materials' pixel shading.
  bool materials = false;
  for (const scene::Material& mat : scene.materials) materials |= mat.needsPixelShading();
  if (o.lod)
    for (const scene::LodGroup& g : scene.lodGroups) materials |= g.fade > 0;
  if (materials)
    return Error{"", "",
                 "the segment pipeline draws vertex colours (and fog): the scene's materials "
                 "need pixel shading (lighting per pixel, texture, translucency or a dissolving "
                 "level of detail)"};
  const bool fog = scene.fog.enabled && scene.fog.beta > 0;
  if (fog && camera.projective)
    return Error{"", "", "the segment pipeline's fog needs a view window, not a sub-frustum"};
  // Stage 3: every instance's vertices to clip space, in the priority order masking draws in.
  RenderOptions po = o;
  po.hsr = RenderOptions::Hsr::priority;
  const auto t0 = core::Clock::now();
  if (Status s = buildDrawPackets(scene, po, camera, nullptr, frame_.pool(), packets_); !s)
    return s;
  stats.vertexMs = core::msSince(t0);
  SegmentSettings ss;
  ss.width = o.width;
  ss.height = o.height;
  ss.clearColor[0] = scene.background.x;
  ss.clearColor[1] = scene.background.y;
  ss.clearColor[2] = scene.background.z;
  ss.timing.wordsPerLine = o.segmentChannel.wordsPerLine;
  ss.timing.criticalLines = o.segmentChannel.criticalLines;
  ss.timing.fifoWords = o.segmentChannel.fifoWords;
  ss.interlaced = o.segmentChannel.interlaced;
  ss.donor = o.segmentChannel.donor;
  ss.fog = fog;
  ss.fogColor[0] = scene.fog.color.x;
  ss.fogColor[1] = scene.fog.color.y;
  ss.fogColor[2] = scene.fog.color.z;
  ss.fogBeta = scene.fog.beta;
  ss.tanLeft = camera.tanLeft;
  ss.tanRight = camera.tanRight;
  ss.tanBottom = camera.tanBottom;
  ss.tanTop = camera.tanTop;
  ss.tent = o.filter == RenderOptions::Filter::tent3;
  segments_.render(packets_, ss, gamma_, frame_.pool(), image, stats);
  return {};
}

}  // namespace sv::render
