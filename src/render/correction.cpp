#include "render/correction.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

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
                       output::LinearImage& out, FrameStats& stats, DisplayStats& cs, Image* image,
                       bool keepLinear) {
  SV_CHECK(view.table != nullptr);
  bool finished = false;  // blended and encoded cell by cell
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
    if (view.blend && (view.blend->width != table.width || view.blend->height != table.height))
      return Error{"", "",
                   fmt::format("blend weights of {} × {} pixels for a projector of {} × {}",
                               view.blend->width, view.blend->height, table.width, table.height)};
    const auto t1 = core::Clock::now();
    SubFrustumStats fs;
    SubFrustumRenderer::Finish finish{view.blend, &renderer.gamma(), image, keepLinear};
    finished = image && o.filter == RenderOptions::Filter::box;
    if (Status s = renderer.cells().render(scene, po, base, view.eye, *plan, table.valid, out,
                                           stats, &fs, finished ? &finish : nullptr);
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
  if (view.blend && !finished) {
    if (view.blend->width != table.width || view.blend->height != table.height)
      return Error{"", "",
                   fmt::format("blend weights of {} × {} pixels for a projector of {} × {}",
                               view.blend->width, view.blend->height, table.width, table.height)};
    const auto t3 = core::Clock::now();
    display::applyBlend(*view.blend, out.rgb.data());
    cs.blendMs = core::msSince(t3);
  }
  if (image && !finished) renderer.encode(out, o, *image);
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
      p.region = r;
      d.projectors.push_back(std::move(p));
    }
  if (d.projectors.empty()) return Error{path, "", "the file has no regions"};
  return d;
}

DisplaySetup scaledDisplay(const DisplaySetup& d, int r) {
  SV_CHECK(r >= 1);
  DisplaySetup out;
  out.rig = d.rig;
  out.eye = d.eye;
  for (size_t i = 0; i < d.projectors.size(); ++i) {
    const ProjectorSetup& p = d.projectors[i];
    const int w = (p.table.width + r - 1) / r, h = (p.table.height + r - 1) / r;
    ProjectorSetup q;
    q.name = p.name;
    q.alpha = p.alpha;
    display::MpcdiRegion region;
    if (out.rig) {
      // The same lens over fewer pixels: the projector's window spans its image's edges.
      display::Projector& projector = out.rig->projectors[i];
      projector.width = w;
      projector.height = h;
      q.table = display::directionTable(out.rig->geometry(int(i)));
      region.alpha = p.alpha;
    } else {
      SV_CHECK(p.region.has_value());
      region = *p.region;
      region.xResolution = w;
      region.yResolution = h;
      // Read from a file already: its warp gave a direction map at full size, so it gives one
      // at this.
      q.table = display::directionTable(display::directionMap(region).value());
      q.region = region;
    }
    region.xResolution = w;
    region.yResolution = h;
    if (region.alpha || region.beta) q.blend = display::blendWeights(region);
    out.projectors.push_back(std::move(q));
  }
  return out;
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

std::shared_ptr<const display::SubFrustumPlan> PlanCache::moved(
    const display::DirectionTable& table, const display::SubFrustumOptions& options,
    const display::DisplayGeometry& design, const display::DisplayGeometry& moved,
    core::ThreadPool* pool, double& madeMs, double& refitMs, display::RefitStats& stats) const {
  std::shared_ptr<const display::SubFrustumPlan> plan = of(table, options, madeMs);
  std::lock_guard lock(mutex_);
  refitMs = 0;
  if (madeMs > 0 || !points_) {  // a new design plan: its screen points, and no moved one yet
    points_ = display::planScreenPoints(*plan, table, design);
    movedPlan_.reset();
  }
  const bool same = movedPlan_ && movedEye_.x == moved.eye.x && movedEye_.y == moved.eye.y &&
                    movedEye_.z == moved.eye.z;
  if (!same) {
    const auto t0 = core::Clock::now();
    movedPlan_ = std::make_shared<const display::SubFrustumPlan>(
        display::refitPlan(*plan, *points_, moved, options, &movedStats_, pool));
    movedEye_ = moved.eye;
    refitMs = core::msSince(t0);
  }
  stats = movedStats_;
  return movedPlan_;
}

Status renderDisplay(CorrectionRenderer& renderer, const scene::Scene& scene,
                     const RenderOptions& o, const DisplaySetup& display, DisplayFrame& frame,
                     const DisplayRequest& request) {
  const Result<FrameCamera> base = chooseCamera(scene, o);
  if (!base.ok()) return base.error();
  const size_t n = display.projectors.size();
  frame.linear.resize(n);
  frame.images.resize(n);
  frame.stats.resize(n);
  frame.correction.resize(n);
  std::vector<int> every;
  if (!request.projectors)
    for (size_t i = 0; i < n; ++i) every.push_back(int(i));
  const Vec3d offset = request.eyeOffset;
  if (!std::isfinite(offset.x) || !std::isfinite(offset.y) || !std::isfinite(offset.z))
    return Error{"", "", "the display's eye offset is not finite"};
  const bool movedEye = offset.x != 0 || offset.y != 0 || offset.z != 0;
  for (const int k : request.projectors ? *request.projectors : every) {
    if (k < 0 || size_t(k) >= n)
      return Error{"", "", fmt::format("projector {} does not exist ({} projectors)", k, n)};
    const size_t i = size_t(k);
    frame.stats[i] = FrameStats{};
    frame.correction[i] = DisplayStats{};
    const ProjectorSetup& p = display.projectors[i];
    CorrectedView view;
    view.table = &p.table;
    view.blend = p.blend ? &*p.blend : nullptr;
    view.eye = display.eye + offset;
    view.correction = o.correction;
    const auto start = core::Clock::now();
    // Method (a)'s plan made once for the display, kept from frame to frame; for a moved eye of a
    // known screen, its maps refitted (kept while the eye stays).
    std::shared_ptr<const display::SubFrustumPlan> plan;
    if (o.correction == RenderOptions::Correction::subFrusta) {
      display::SubFrustumOptions so;
      so.znear = base.value().camera.znear;
      so.zfar = base.value().camera.zfar;
      DisplayStats& cs = frame.correction[i];
      if (movedEye && display.rig) {
        const display::DisplayGeometry design = display.rig->geometry(int(i));
        display::DisplayGeometry moved = design;
        moved.eye = {float(design.eye.x + offset.x), float(design.eye.y + offset.y),
                     float(design.eye.z + offset.z)};
        display::RefitStats rs;
        plan =
            p.plan.moved(p.table, so, design, moved, &renderer.pool(), cs.planMs, cs.refitMs, rs);
        cs.replannedCells = rs.replanned;
      } else {
        plan = p.plan.of(p.table, so, cs.planMs);
      }
      view.plan = plan.get();
    }
    if (Status s =
            renderCorrected(renderer, scene, o, base.value(), view, frame.linear[i], frame.stats[i],
                            frame.correction[i], &frame.images[i], request.keepLinear);
        !s) {
      Error e = s.error();
      e.message = fmt::format("projector '{}': {}", p.name, e.message);
      return e;
    }
    frame.stats[i].totalMs = core::msSince(start);
  }
  return {};
}

display::PanoramaView displayPanorama(const DisplaySetup& display, double pixelDegrees) {
  std::vector<const display::DirectionTable*> tables;
  for (const ProjectorSetup& p : display.projectors) tables.push_back(&p.table);
  display::PanoramaView view = display::panoramaOf(tables, pixelDegrees);
  // At most kMaxRasterSize a side (a picture of 8192² is 200 MB): coarser pixels beyond.
  const int side = std::max(view.width, view.height);
  if (side > kMaxRasterSize)
    view = display::panoramaOf(tables, pixelDegrees * double(side) / (kMaxRasterSize - 2));
  return view;
}

namespace {

// The linear value an 8-bit code stands for under `gamma`: the middle of the values it encodes.
std::array<uint16_t, 256> decodeTable(const output::GammaTable& gamma) {
  std::array<uint32_t, 256> lo, hi;
  lo.fill(65535);
  hi.fill(0);
  for (uint32_t v = 0; v < 65536; ++v) {
    const uint8_t c = gamma.table[v];
    lo[c] = std::min(lo[c], v), hi[c] = std::max(hi[c], v);
  }
  std::array<uint16_t, 256> out{};
  uint16_t last = 0;
  for (size_t c = 0; c < 256; ++c) {
    if (lo[c] <= hi[c]) last = uint16_t((lo[c] + hi[c]) / 2);
    out[c] = last;  // a code no value encodes: the one below's
  }
  return out;
}

}  // namespace

void showPanorama(const DisplaySetup& display, const display::PanoramaView& view,
                  const Image& picture, const output::GammaTable& gamma, core::ThreadPool& pool,
                  std::vector<Image>& images) {
  SV_CHECK(picture.width == view.width && picture.height == view.height);
  const std::array<uint16_t, 256> decode = decodeTable(gamma);
  images.resize(display.projectors.size());
  output::LinearImage linear;
  for (size_t k = 0; k < display.projectors.size(); ++k) {
    const ProjectorSetup& p = display.projectors[k];
    const display::DirectionTable& t = p.table;
    linear.resize(t.width, t.height);
    constexpr int kBand = 16;  // rows per task
    pool.parallelFor(size_t((t.height + kBand - 1) / kBand), [&](size_t band, int) {
      const int y0 = int(band) * kBand, y1 = std::min(t.height, y0 + kBand);
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < t.width; ++x) {
          const size_t i = t.index(x, y);
          uint16_t* out = &linear.rgb[3 * i];
          out[0] = out[1] = out[2] = 0;
          if (!t.valid[i]) continue;
          // Bilinear between the four pixel centres around the point, clamped at the edges.
          const display::PanoramaPoint q = display::panoramaPoint(view, t.directions[i]);
          const double fx = std::clamp(q.x - 0.5, 0.0, double(view.width - 1));
          const double fy = std::clamp(q.y - 0.5, 0.0, double(view.height - 1));
          const int x0 = int(fx), y0p = int(fy);
          const int x1 = std::min(x0 + 1, view.width - 1), y1p = std::min(y0p + 1, view.height - 1);
          const double ax = fx - x0, ay = fy - y0p;
          for (int c = 0; c < 3; ++c) {
            const auto at = [&](int px, int py) {
              return double(decode[picture.pixel(px, py)[c]]);
            };
            const double top = at(x0, y0p) + ax * (at(x1, y0p) - at(x0, y0p));
            const double bottom = at(x0, y1p) + ax * (at(x1, y1p) - at(x0, y1p));
            out[c] = uint16_t(std::lround(top + ay * (bottom - top)));
          }
        }
    });
    if (p.blend) display::applyBlend(*p.blend, linear.rgb.data());
    output::prepareImage(t.width, t.height, images[k]);
    pool.parallelFor(size_t((t.height + kBand - 1) / kBand), [&](size_t band, int) {
      const int y0 = int(band) * kBand;
      output::encodeRows(linear, gamma, y0, std::min(t.height, y0 + kBand), images[k]);
    });
  }
}

PanoramaPatch panoramaPatch(const DisplaySetup& display, const display::PanoramaView& view, int x0,
                            int y0, int width, int height) {
  PanoramaPatch patch;
  patch.x0 = x0, patch.y0 = y0, patch.width = width, patch.height = height;
  for (const ProjectorSetup& p : display.projectors) {
    const display::DirectionTable& t = p.table;
    std::vector<PanoramaPatch::Pixel>& pixels = patch.pixels.emplace_back();
    for (size_t i = 0; i < t.directions.size(); ++i) {
      if (!t.valid[i]) continue;
      const display::PanoramaPoint q = display::panoramaPoint(view, t.directions[i]);
      const double px = std::floor(q.x) - x0, py = std::floor(q.y) - y0;
      if (px >= 0 && px < width && py >= 0 && py < height)
        pixels.push_back({uint32_t(i), uint32_t(py) * uint32_t(width) + uint32_t(px)});
    }
  }
  return patch;
}

void overlayPatch(const PanoramaPatch& patch, const Image& onBlack, const Image& onWhite,
                  std::vector<Image>& images) {
  SV_CHECK(onBlack.width == patch.width && onBlack.height == patch.height &&
           onWhite.width == patch.width && onWhite.height == patch.height);
  for (size_t k = 0; k < patch.pixels.size() && k < images.size(); ++k) {
    if (images[k].rgb.empty()) continue;  // a projector not drawn here
    for (const PanoramaPatch::Pixel& px : patch.pixels[k])
      for (size_t c = 0; c < 3; ++c) {
        const int add = onBlack.rgb[3 * size_t(px.at) + c];
        const int white = onWhite.rgb[3 * size_t(px.at) + c];
        uint8_t& v = images[k].rgb[3 * size_t(px.pixel) + c];
        v = uint8_t(std::clamp(add + (v * (white - add) + 127) / 255, 0, 255));
      }
  }
}

Result<Image> viewerImage(const DisplaySetup& display, const std::vector<Image>& frames,
                          const display::PanoramaView& view, const output::GammaTable& gamma) {
  if (frames.size() != display.projectors.size())
    return Error{"", "",
                 fmt::format("{} frames for a display of {} projectors", frames.size(),
                             display.projectors.size())};
  const std::array<uint16_t, 256> decode = decodeTable(gamma);
  DisplayFrame frame;
  frame.linear.resize(frames.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    const display::DirectionTable& t = display.projectors[i].table;
    if (frames[i].width != t.width || frames[i].height != t.height)
      return Error{"", "",
                   fmt::format("projector '{}': a frame of {} × {} for {} × {} pixels",
                               display.projectors[i].name, frames[i].width, frames[i].height,
                               t.width, t.height)};
    frame.linear[i].resize(t.width, t.height);
    for (size_t k = 0; k < frames[i].rgb.size(); ++k)
      frame.linear[i].rgb[k] = decode[frames[i].rgb[k]];
  }
  return viewerImage(display, frame, view, gamma);
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
