#include "render/correction.h"

#include <fmt/format.h>

#include <algorithm>

#include "core/check.h"
#include "core/timing.h"

namespace sv::render {

CorrectionRenderer::CorrectionRenderer(const RenderOptions& options)
    : options_(options), gamma_(gammaTableOf(options)), pool_(resolveThreads(options.threads)) {}

void CorrectionRenderer::encode(const output::LinearImage& linear, const RenderOptions& o,
                                Image& image) {
  output::prepareImage(linear.width, linear.height, image);
  constexpr int kBand = 16;  // rows per task
  pool_.parallelFor(size_t((linear.height + kBand - 1) / kBand), [&](size_t band, int) {
    const int y0 = int(band) * kBand, y1 = std::min(linear.height, y0 + kBand);
    if (o.filter == RenderOptions::Filter::tent3)
      output::tentFilterRows(linear, gamma_, y0, y1, image);
    else
      output::encodeRows(linear, gamma_, y0, y1, image);
  });
}

SubFrustumRenderer& CorrectionRenderer::cells() {
  if (!cells_) cells_.emplace(options_);
  return *cells_;
}

ViewRenderer& CorrectionRenderer::flat() {
  if (!flat_) flat_.emplace(options_);
  return *flat_;
}

display::DirectionMap directionMapOf(const display::DirectionTable& table) {
  display::DirectionMap map;
  map.width = table.width;
  map.height = table.height;
  map.valid = table.valid;
  map.directions.reserve(table.directions.size());
  for (const Vec3d& d : table.directions)
    map.directions.push_back({float(d.x), float(d.y), float(d.z)});
  return map;
}

Status renderCorrected(CorrectionRenderer& renderer, const scene::Scene& scene,
                       const RenderOptions& o, const FrameCamera& base, const CorrectedView& view,
                       output::LinearImage& out, FrameStats& stats, DisplayStats& cs) {
  SV_CHECK(view.table != nullptr);
  const display::DirectionTable& table = *view.table;
  RenderOptions po = o;
  po.width = table.width;
  po.height = table.height;
  if (Status s = validate(po); !s) return s;
  if (view.correction == RenderOptions::Correction::subFrusta) {
    // Method (a): the plan (given, or made here), then every cell through its own map.
    std::optional<display::SubFrustumPlan> own;
    const display::SubFrustumPlan* plan = view.plan;
    if (!plan) {
      const auto t0 = core::Clock::now();
      display::SubFrustumOptions so;
      so.znear = base.camera.znear;
      so.zfar = base.camera.zfar;
      own = display::planSubFrusta(table, so);
      plan = &*own;
      cs.planMs = core::msSince(t0);
    }
    const auto t1 = core::Clock::now();
    SubFrustumStats fs;
    if (Status s =
            renderer.cells().render(scene, po, base, view.eye, *plan, table.valid, out, stats, &fs);
        !s)
      return s;
    cs.renderMs = core::msSince(t1);
    cs.cells = fs.cells;
    cs.maxResidualPixels = fs.maxResidualPixels;
  } else {
    // Method (b): the flat view rendered as a channel from the eye, then resampled through the
    // warp, in row bands on the flat renderer's threads.
    std::optional<display::ResampleWarp> own;
    const display::ResampleWarp* warp = view.warp;
    if (!warp) {
      const auto t0 = core::Clock::now();
      Result<display::ResampleWarp> made = resampleWarpOf(table, view.marginPixels);
      if (!made.ok()) return made.error();
      own = std::move(made).value();
      warp = &*own;
      cs.warpMs = core::msSince(t0);
    }
    if (warp->width != table.width || warp->height != table.height)
      return Error{"", "",
                   fmt::format("a warp of {} × {} pixels for a projector of {} × {}", warp->width,
                               warp->height, table.width, table.height)};
    const display::FlatView& f = warp->view;
    scene::Channel c;
    c.width = f.width;
    c.height = f.height;
    c.yawDegrees = float(f.orientation.yawDegrees);
    c.pitchDegrees = float(f.orientation.pitchDegrees);
    c.rollDegrees = float(f.orientation.rollDegrees);
    c.offset = {float(view.eye.x), float(view.eye.y), float(view.eye.z)};
    c.frustum = scene::ChannelFrustum{float(f.window.leftDegrees), float(f.window.rightDegrees),
                                      float(f.window.downDegrees), float(f.window.upDegrees)};
    RenderOptions fo = o;
    fo.width = f.width;
    fo.height = f.height;
    if (Status s = validate(fo); !s) return s;
    const Result<FrameCamera> camera = channelCamera(scene, fo, c);
    if (!camera.ok()) return camera.error();
    const auto t1 = core::Clock::now();
    ViewRenderer& flat = renderer.flat();
    if (Status s = flat.renderLinear(scene, fo, camera.value(), renderer.flatImage(), stats); !s)
      return s;
    cs.renderMs = core::msSince(t1);
    const auto t2 = core::Clock::now();
    out.resize(table.width, table.height);
    const display::ResampleFilter filter = view.correction == RenderOptions::Correction::bicubic
                                               ? display::ResampleFilter::bicubic
                                               : display::ResampleFilter::bilinear;
    constexpr int kBand = 16;  // rows per task
    const uint16_t* flatRgb = renderer.flatImage().rgb.data();
    renderer.pool().parallelFor(size_t((table.height + kBand - 1) / kBand), [&](size_t band, int) {
      const int y0 = int(band) * kBand;
      display::resampleRows(*warp, flatRgb, filter, y0, std::min(table.height, y0 + kBand),
                            out.rgb.data());
    });
    cs.resampleMs = core::msSince(t2);
    cs.flatWidth = f.width;
    cs.flatHeight = f.height;
    cs.outside = warp->outside;
  }
  if (view.blend) {
    if (view.blend->width != table.width || view.blend->height != table.height)
      return Error{"", "",
                   fmt::format("blend weights of {} × {} pixels for a projector of {} × {}",
                               view.blend->width, view.blend->height, table.width, table.height)};
    const auto t3 = core::Clock::now();
    display::applyBlend(*view.blend, out.rgb.data());
    cs.blendMs = core::msSince(t3);
  }
  return {};
}

Result<display::ResampleWarp> resampleWarpOf(const display::DirectionTable& table,
                                             int marginPixels) {
  const display::DirectionMap map = directionMapOf(table);
  const Result<display::FlatView> flat =
      display::coveringFlatView(map, display::meanOrientation(map), marginPixels);
  if (!flat.ok()) return flat.error();
  return display::resampleWarp(flat.value(), map);
}

DisplaySetup cylinderDisplay(int width, int height, double overlapDegrees) {
  DisplaySetup d;
  d.rig = display::threeProjectorCylinder(3, overlapDegrees, width, height);
  d.eye = {d.rig->eye.x, d.rig->eye.y, d.rig->eye.z};
  const std::vector<display::BlendMap> alpha = display::cylinderAlphaMaps(
      *d.rig, overlapDegrees, std::max(1, width / 2), std::max(1, height / 2));
  const char* names[3] = {"left", "centre", "right"};
  for (size_t i = 0; i < d.rig->projectors.size(); ++i) {
    ProjectorSetup p;
    p.name = names[i];
    p.table = display::directionTable(d.rig->geometry(int(i)));
    p.alpha = alpha[i];
    display::MpcdiRegion region;
    region.xResolution = width;
    region.yResolution = height;
    region.alpha = p.alpha;
    p.blend = display::blendWeights(region);
    d.projectors.push_back(std::move(p));
  }
  return d;
}

Result<DisplaySetup> mpcdiDisplay(const std::string& path) {
  Result<display::Mpcdi> m = display::readMpcdi(path);
  if (!m.ok()) return m.error();
  if (m->profile != display::MpcdiProfile::simulation3d)
    return Error{path, "",
                 "a 2d-profile file maps pixels to content, not to directions: distortion "
                 "correction needs the 3d profile"};
  DisplaySetup d;
  for (const display::MpcdiBuffer& b : m->buffers)
    for (const display::MpcdiRegion& r : b.regions) {
      Result<display::DirectionMap> map = display::directionMap(r);
      if (!map.ok()) {
        Error e = map.error();
        if (e.file.empty()) e.file = path;
        return e;
      }
      ProjectorSetup p;
      p.name = r.id;
      p.table = display::directionTable(map.value());
      if (r.alpha || r.beta) p.blend = display::blendWeights(r);
      d.projectors.push_back(std::move(p));
    }
  if (d.projectors.empty()) return Error{path, "", "the file has no regions"};
  return d;
}

Result<display::Mpcdi> mpcdiOf(const DisplaySetup& d) {
  if (!d.rig) return Error{"", "", "only an analytic rig can be written as MPCDI"};
  const display::CylinderRig& rig = *d.rig;
  display::Mpcdi m;
  m.level = 2;  // a warp per pixel
  display::MpcdiBuffer buffer;
  buffer.id = "display";
  for (size_t i = 0; i < rig.projectors.size(); ++i) {
    const display::Projector& pr = rig.projectors[i];
    const display::DirectionMap map = directionMapOf(d.projectors[i].table);
    const Result<display::FlatView> flat =
        display::coveringFlatView(map, display::meanOrientation(map), 2);
    if (!flat.ok()) return flat.error();
    display::MpcdiRegion r =
        display::regionFromGeometry(rig.geometry(int(i)), {flat->orientation, flat->window},
                                    pr.width, pr.height, d.projectors[i].name);
    r.alpha = d.projectors[i].alpha;
    buffer.xResolution += pr.width;
    buffer.yResolution = std::max(buffer.yResolution, pr.height);
    buffer.regions.push_back(std::move(r));
  }
  // The regions side by side in the buffer.
  double x = 0;
  for (display::MpcdiRegion& r : buffer.regions) {
    r.x = x / buffer.xResolution;
    r.y = 0;
    r.xSize = double(r.xResolution) / buffer.xResolution;
    r.ySize = double(r.yResolution) / buffer.yResolution;
    x += r.xResolution;
  }
  m.buffers.push_back(std::move(buffer));
  return m;
}

std::shared_ptr<const display::SubFrustumPlan> PlanCache::of(
    const display::DirectionTable& table, const display::SubFrustumOptions& options,
    double& madeMs) const {
  std::lock_guard lock(mutex_);
  madeMs = 0;
  const auto same = [](const display::SubFrustumOptions& a, const display::SubFrustumOptions& b) {
    return a.boundPixels == b.boundPixels && a.minCellSize == b.minCellSize && a.znear == b.znear &&
           a.zfar == b.zfar;
  };
  if (!plan_ || !same(options, options_)) {
    const auto t0 = core::Clock::now();
    plan_ = std::make_shared<const display::SubFrustumPlan>(display::planSubFrusta(table, options));
    options_ = options;
    madeMs = core::msSince(t0);
  }
  return plan_;
}

Status renderDisplay(CorrectionRenderer& renderer, const scene::Scene& scene,
                     const RenderOptions& o, const DisplaySetup& display, DisplayFrame& frame) {
  const Result<FrameCamera> base = chooseCamera(scene, o);
  if (!base.ok()) return base.error();
  const size_t n = display.projectors.size();
  frame.linear.resize(n);
  frame.images.resize(n);
  frame.stats.assign(n, FrameStats{});
  frame.correction.assign(n, DisplayStats{});
  for (size_t i = 0; i < n; ++i) {
    const ProjectorSetup& p = display.projectors[i];
    CorrectedView view;
    view.table = &p.table;
    view.blend = p.blend ? &*p.blend : nullptr;
    view.eye = display.eye;
    view.correction = o.correction;
    const auto start = core::Clock::now();
    // Method (a)'s plan made once for the display, kept from frame to frame.
    std::shared_ptr<const display::SubFrustumPlan> plan;
    if (o.correction == RenderOptions::Correction::subFrusta) {
      display::SubFrustumOptions so;
      so.znear = base.value().camera.znear;
      so.zfar = base.value().camera.zfar;
      plan = p.plan.of(p.table, so, frame.correction[i].planMs);
      view.plan = plan.get();
    }
    if (Status s = renderCorrected(renderer, scene, o, base.value(), view, frame.linear[i],
                                   frame.stats[i], frame.correction[i]);
        !s) {
      Error e = s.error();
      e.message = fmt::format("projector '{}': {}", p.name, e.message);
      return e;
    }
    const output::LinearImage& linear = frame.linear[i];
    renderer.encode(linear, o, frame.images[i]);
    frame.stats[i].totalMs = core::msSince(start);
  }
  return {};
}

Result<Image> viewerImage(const DisplaySetup& display, const DisplayFrame& frame,
                          const display::PanoramaView& view, const output::GammaTable& gamma) {
  if (!display.rig) return Error{"", "", "the simulated viewer needs the display's geometry"};
  std::vector<const uint16_t*> images;
  for (const output::LinearImage& l : frame.linear) images.push_back(l.rgb.data());
  display::ResampledImage r = display::viewerPanorama(display.rig->screen, display.rig->eye,
                                                      display.rig->projectors, images, view);
  output::LinearImage linear;
  linear.width = r.width;
  linear.height = r.height;
  linear.rgb = std::move(r.rgb);
  Image image;
  output::prepareImage(linear.width, linear.height, image);
  output::encodeRows(linear, gamma, 0, linear.height, image);
  return image;
}

}  // namespace sv::render
