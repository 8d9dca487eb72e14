// The one place that wires a frame together (STYLE.md habit 1): scene → camera → draw packets →
// setup and tiles, with the frame's passes → resolve. Each stage call's work lives in the file
// named for it (docs/ARCHITECTURE.md).
#include <algorithm>
#include <thread>

#include "core/timing.h"
#include "render/camera.h"
#include "render/draw_packets.h"
#include "render/frame_renderer.h"
#include "render/frame_settings.h"
#include "render/passes.h"
#include "render/resolve_sink.h"
#include "render/shading_tables.h"
#include "synthvis/render.h"

namespace sv {
namespace {

int resolveThreads(int requested) {
  if (requested > 0) return requested;
  return std::clamp(int(std::thread::hardware_concurrency()), 1, kMaxThreads);
}

}  // namespace

// What a Renderer keeps from frame to frame: its threads, tables and buffers.
struct Renderer::Impl {
  explicit Impl(const RenderOptions& o)
      : options(o),
        frame(resolveThreads(o.threads)),
        gamma(o.gamma == 0 ? output::GammaTable::srgb() : output::GammaTable::power(o.gamma)) {}
  RenderOptions options;
  render::FrameRenderer frame;
  output::GammaTable gamma;
  render::ShadingTables shading;
  render::DrawPackets packets;
  output::LinearImage linear;  // the box-resolved frame, for the tent filter
  render::FramePasses passes;
};

Renderer::Renderer(const RenderOptions& options) : impl_(std::make_unique<Impl>(options)) {}
Renderer::~Renderer() = default;
const RenderOptions& Renderer::options() const { return impl_->options; }

Status Renderer::render(const scene::Scene& scene, Image& image, FrameStats* statsOut) {
  Impl& m = *impl_;
  const RenderOptions& o = m.options;
  if (Status s = validate(o); !s) return s;
  // Vertices and indices are checked as the vertex stage reads them (buildDrawPackets).
  if (Status s = scene::validate(scene, "", false); !s) return s;
  FrameStats stats;
  const auto start = core::Clock::now();

  // Stage 2: the camera, and the shading stage's tables in its eye space.
  const Result<render::FrameCamera> camera = render::chooseCamera(scene, o);
  if (!camera.ok()) return camera.error();
  render::buildShading(scene, o, camera.value().view, m.shading);
  const bool pixelShading = m.shading.any && o.debugView == RenderOptions::DebugView::none;

  // Stage 3: every instance's vertices to clip space, in draw order.
  const auto t0 = core::Clock::now();
  if (Status s = render::buildDrawPackets(
          scene, o, camera.value(), pixelShading ? &m.shading : nullptr, m.frame.pool(), m.packets);
      !s)
    return s;
  stats.vertexMs = core::msSince(t0);

  // Stages 3–5: setup and the tiles, with the frame's passes, each tile resolved when finished.
  Result<render::FrameSettings> settings = render::makeFrameSettings(
      o, scene.background, m.shading.environment, pixelShading, m.packets.indices.size() / 3);
  if (!settings.ok()) return settings.error();
  render::FrameSettings& fs = settings.value();
  render::ResolveSink sink(o, m.gamma, m.linear, image);
  fs.finishTile = sink.finishTile((fs.width + raster::kTileSize - 1) >> raster::kTileLog2);
  fs.colorSums = sink.takesColorSums();
  fs.passes = m.passes.compose(scene, o, camera.value(), m.shading);
  output::prepareImage(o.width, o.height, image);
  m.frame.render(m.packets, fs, stats);
  stats.rasterMs += sink.finish(m.frame.pool());

  stats.totalMs = core::msSince(start);
  if (statsOut) *statsOut = stats;
  return {};
}

}  // namespace sv
