// The public entry point (synthvis/render.h): the classic view and the display channels, each a
// view through render/view_renderer.h, the one place that wires a view together (scene → camera →
// draw packets → setup and tiles, with the frame's passes → resolve).
#include <fmt/format.h>

#include <algorithm>
#include <optional>

#include "core/timing.h"
#include "lights/light_pass.h"
#include "render/camera.h"
#include "render/correction.h"
#include "render/passes.h"
#include "render/view_renderer.h"
#include "synthvis/render.h"

namespace sv {

// What a Renderer keeps from frame to frame: its options, and its threads, tables and buffers;
// for a display, its cells' and flat view's renderers (made on its first frame) and its last frame
// (the viewer's input).
struct Renderer::Impl {
  explicit Impl(const RenderOptions& o) : options(o), view(o) {}
  RenderOptions options;
  render::ViewRenderer view;
  std::optional<render::CorrectionRenderer> display;
  render::DisplayFrame displayFrame;
  std::optional<Display> displayDrawn;  // what displayFrame shows (held: its tables stay)
  lights::LightLaws lightLaws;          // renderChannels': the frame's, for the channels' eye
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
  const auto start = core::Clock::now();
  const Result<render::FrameCamera> camera = render::chooseCamera(scene, o);
  if (!camera.ok()) return camera.error();
  FrameStats stats;
  if (Status s = m.view.render(scene, o, camera.value(), image, stats); !s) return s;
  stats.totalMs = core::msSince(start);
  if (statsOut) *statsOut = stats;
  return {};
}

// SPEC §9: every channel of one scene at one instant. The channels are rendered one after another,
// each a whole frame on the renderer's one thread pool (its tiles shared among all threads), into
// its own image at its own size; the scene's draw order, tables and passes are rebuilt per channel
// from its camera.
Status Renderer::renderChannels(const scene::Scene& scene, std::vector<Image>& images,
                                std::vector<FrameStats>* statsOut,
                                const std::vector<ChannelShare>* only) {
  Impl& m = *impl_;
  if (scene.channels.empty()) {  // the classic view (render validates)
    if (only) return Error{"", "", "a share of the channels needs a scene with display channels"};
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
  // Issue 60: the light points' laws once for the channels that share an eye — those without an
  // offset, turned from one camera — and per channel only the projection. Worked out anew each
  // frame (the scene's groups, blinking, fog may have changed), at the camera's eye before the
  // channel's turn: a view of that camera alone (render) finds the same bits.
  bool lawsThisFrame = false;
  for (size_t i = 0; i < n; ++i) {
    const auto share = only ? std::find_if(only->begin(), only->end(),
                                           [&](const ChannelShare& c) { return c.channel == int(i); })
                            : std::vector<ChannelShare>::const_iterator{};
    if (only && share == only->end()) continue;
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
    Result<render::FrameCamera> camera = render::channelCamera(scene, o, channel);
    if (!camera.ok()) return camera.error();
    if (!scene.lightPoints.empty() && channel.offset == Vec3{0, 0, 0}) {
      const Result<render::FrameCamera> base = render::chooseCamera(scene, o);
      if (!base.ok()) return base.error();
      const Vec3 eye = lights::viewEye(base.value().view);
      const Vec3 kept = m.lightLaws.eye();
      if (!lawsThisFrame || !(eye.x == kept.x && eye.y == kept.y && eye.z == kept.z))
        m.lightLaws.compute(render::lightInput(scene, base.value()), m.view.pool());
      lawsThisFrame = true;
      camera.value().lightLaws = &m.lightLaws;
    }
    if (Status s = m.view.render(scene, o, camera.value(), images[i], stats[i],
                                 only ? share->tiles : TileShare{});
        !s) {
      Error e = s.error();
      if (only) e.message = fmt::format("channels[{}]: {}", i, e.message);
      return e;
    }
    stats[i].totalMs = core::msSince(start);
  }
  if (statsOut) *statsOut = std::move(stats);
  return {};
}

// SPEC §9, §12: every projector of a curved-screen display, pre-distorted and blended
// (render/correction.h); the frames kept in linear light for the viewer.
Status Renderer::renderDisplay(const scene::Scene& scene, const Display& display,
                               std::vector<Image>& images, std::vector<FrameStats>* stats,
                               std::vector<DisplayStats>* correction, const DisplayView& view) {
  Impl& m = *impl_;
  if (Status s = validate(m.options); !s) return s;
  if (Status s = scene::validate(scene, "", false); !s) return s;
  if (!m.display) m.display.emplace(m.options);
  m.displayDrawn.reset();
  render::DisplayRequest request;
  request.eyeOffset = {view.eyeOffset[0], view.eyeOffset[1], view.eyeOffset[2]};
  if (!view.projectors.empty()) request.projectors = &view.projectors;
  request.keepLinear = view.keepLinear;
  if (Status s = render::renderDisplay(*m.display, scene, m.options, display.setup(),
                                       m.displayFrame, request);
      !s)
    return s;
  if (view.keepLinear) m.displayDrawn = display;
  // The drawn projectors' frames handed over, not copied (18 MB a frame for three at 1080p): the
  // renderer reuses the caller's old buffers next time.
  const size_t n = size_t(display.projectorCount());
  images.resize(n);
  if (stats) stats->resize(n);
  if (correction) correction->resize(n);
  for (size_t i = 0; i < n; ++i) {
    if (!view.projectors.empty() &&
        std::find(view.projectors.begin(), view.projectors.end(), int(i)) == view.projectors.end())
      continue;
    std::swap(images[i], m.displayFrame.images[i]);
    if (stats) (*stats)[i] = m.displayFrame.stats[i];
    if (correction) (*correction)[i] = m.displayFrame.correction[i];
  }
  return {};
}

Result<Image> Renderer::viewerImage(const Display& display) const {
  const Impl& m = *impl_;
  if (!m.displayDrawn || &m.displayDrawn->setup() != &display.setup())
    return Error{"", "",
                 "the viewer sees a display this renderer drew last (renderDisplay), its frames "
                 "kept in linear light (DisplayView::keepLinear)"};
  return render::viewerImage(display.setup(), m.displayFrame, display::PanoramaView{},
                             m.display->gamma());
}

}  // namespace sv
