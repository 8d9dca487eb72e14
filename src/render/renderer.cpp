// The one place that wires a frame together (STYLE.md habit 1): scene → camera → draw packets →
// setup and tiles, with the frame's passes → resolve. Each stage call's work lives in the file
// named for it (docs/ARCHITECTURE.md).
#include <fmt/format.h>

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

  Status renderView(const scene::Scene& scene, const RenderOptions& o,
                    const render::FrameCamera& camera, Image& image, FrameStats& stats);
};

Renderer::Renderer(const RenderOptions& options) : impl_(std::make_unique<Impl>(options)) {}
Renderer::~Renderer() = default;
const RenderOptions& Renderer::options() const { return impl_->options; }

// One view of the frame: the classic camera's, or a display channel's (SPEC §9). `o` is the
// renderer's options at this view's size.
Status Renderer::Impl::renderView(const scene::Scene& scene, const RenderOptions& o,
                                  const render::FrameCamera& camera, Image& image,
                                  FrameStats& stats) {
  const auto start = core::Clock::now();
  // Stage 2: the shading stage's tables in the camera's eye space.
  render::buildShading(scene, o, camera.view, shading);
  const bool pixelShading = shading.any && o.debugView == RenderOptions::DebugView::none;

  // Stage 3: every instance's vertices to clip space, in draw order.
  const auto t0 = core::Clock::now();
  if (Status s = render::buildDrawPackets(scene, o, camera, pixelShading ? &shading : nullptr,
                                          frame.pool(), packets);
      !s)
    return s;
  stats.vertexMs = core::msSince(t0);

  // Stages 3–5: setup and the tiles, with the frame's passes, each tile resolved when finished.
  Result<render::FrameSettings> settings = render::makeFrameSettings(
      o, scene.background, shading.environment, pixelShading, packets.indices.size() / 3);
  if (!settings.ok()) return settings.error();
  render::FrameSettings& fs = settings.value();
  render::ResolveSink sink(o, gamma, linear, image);
  fs.finishTile = sink.finishTile((fs.width + raster::kTileSize - 1) >> raster::kTileLog2);
  fs.colorSums = sink.takesColorSums();
  fs.passes = passes.compose(scene, o, camera, shading);
  output::prepareImage(o.width, o.height, image);
  frame.render(packets, fs, stats);
  stats.rasterMs += sink.finish(frame.pool());
  stats.totalMs = core::msSince(start);
  return {};
}

Status Renderer::render(const scene::Scene& scene, Image& image, FrameStats* statsOut) {
  Impl& m = *impl_;
  const RenderOptions& o = m.options;
  if (Status s = validate(o); !s) return s;
  // Vertices and indices are checked as the vertex stage reads them (buildDrawPackets).
  if (Status s = scene::validate(scene, "", false); !s) return s;
  const auto start = core::Clock::now();
  const Result<render::FrameCamera> camera = render::chooseCamera(scene, o);
  if (!camera.ok()) return camera.error();
  FrameStats stats;
  if (Status s = m.renderView(scene, o, camera.value(), image, stats); !s) return s;
  stats.totalMs = core::msSince(start);
  if (statsOut) *statsOut = stats;
  return {};
}

// SPEC §9: every channel of one scene at one instant. The channels are rendered one after another,
// each a whole frame on the renderer's one thread pool (its tiles shared among all threads), into
// its own image at its own size; the scene's draw order, tables and passes are rebuilt per channel
// from its camera.
Status Renderer::renderChannels(const scene::Scene& scene, std::vector<Image>& images,
                                std::vector<FrameStats>* statsOut) {
  Impl& m = *impl_;
  if (scene.channels.empty()) {  // the classic view (render validates)
    images.resize(1);
    FrameStats stats;
    if (Status s = render(scene, images[0], &stats); !s) return s;
    if (statsOut) statsOut->assign(1, stats);
    return {};
  }
  if (Status s = validate(m.options); !s) return s;
  if (Status s = scene::validate(scene, "", false); !s) return s;
  const size_t n = scene.channels.size();
  images.resize(n);
  std::vector<FrameStats> stats(n);
  for (size_t i = 0; i < n; ++i) {
    const scene::Channel& channel = scene.channels[i];
    RenderOptions o = m.options;
    o.width = channel.width;
    o.height = channel.height;
    if (Status s = validate(o); !s) {
      Error e = s.error();
      e.message = fmt::format("channels[{}]: {}", i, e.message);
      return e;
    }
    const auto start = core::Clock::now();
    const Result<render::FrameCamera> camera = render::channelCamera(scene, o, channel);
    if (!camera.ok()) return camera.error();
    if (Status s = m.renderView(scene, o, camera.value(), images[i], stats[i]); !s) return s;
    stats[i].totalMs = core::msSince(start);
  }
  if (statsOut) *statsOut = std::move(stats);
  return {};
}

}  // namespace sv
