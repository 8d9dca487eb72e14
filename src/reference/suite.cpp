#include <fmt/format.h>
#include <hwy/targets.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>

#include "core/timing.h"
#include "reference/gl_renderer.h"
#include "reference/vtk_volume.h"
#include "render/correction.h"
#include "render/view_renderer.h"
#include "synthvis/bench.h"
#include "synthvis/files.h"
#include "synthvis/formats.h"

namespace sv::reference {
namespace {

using core::Clock;
using core::msSince;

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

void finish(RendererRun& r) {
  r.medianMs = median(r.frameMs);
  r.minMs = r.frameMs.empty() ? 0 : *std::min_element(r.frameMs.begin(), r.frameMs.end());
  r.maxMs = r.frameMs.empty() ? 0 : *std::max_element(r.frameMs.begin(), r.frameMs.end());
}

BenchCase trisCase(int count, double area) {
  BenchCase c;
  c.generator = generators::Generator::tris;
  c.tris.count = count;
  c.tris.area = area;
  const std::string n =
      count % 1000000 == 0 ? fmt::format("{}M", count / 1000000) : fmt::format("{}k", count / 1000);
  c.name = fmt::format("tris-{}-a{}", n, area);
  return c;
}

BenchCase layersCase(int layers, generators::SubmitOrder order) {
  BenchCase c;
  c.generator = generators::Generator::layers;
  c.layers.layers = layers;
  c.layers.order = order;
  c.name = fmt::format("layers-d{}-{}", layers, generators::submitOrderName(order));
  return c;
}

}  // namespace

Result<std::vector<BenchCase>> suiteCases(const std::string& suite) {
  using generators::SubmitOrder;
  std::vector<BenchCase> cases;
  if (suite == "quick") {
    for (int count : {10000, 100000})
      for (double area : {10.0, 100.0, 1000.0}) cases.push_back(trisCase(count, area));
    cases.push_back(layersCase(4, SubmitOrder::random));
  } else if (suite == "full") {
    for (int count : {10000, 100000, 1000000})
      for (double area : {10.0, 100.0, 1000.0})
        if (double(count) * area <= 1e8) cases.push_back(trisCase(count, area));
    for (int d : {1, 2, 4, 8, 16})
      for (SubmitOrder o :
           {SubmitOrder::random, SubmitOrder::frontToBack, SubmitOrder::backToFront})
        cases.push_back(layersCase(d, o));
    // Free forms (issue 7), at the suite's raster; the gl reference draws them tessellated.
    for (const generators::Generator g :
         {generators::Generator::freeform, generators::Generator::freeformOne}) {
      BenchCase c;
      c.generator = g;
      c.name = generators::generatorName(g);
      cases.push_back(c);
    }
    // Terrain (issue 29) at 1024² heights, the size whose full-resolution grid the gl reference
    // draws (2.1 M triangles).
    BenchCase t;
    t.generator = generators::Generator::terrain;
    t.terrain.size = 1024;
    t.name = "terrain-1024";
    cases.push_back(t);
  } else {
    return Error{"", "", fmt::format("unknown suite '{}' (quick or full)", suite)};
  }
  return cases;
}

Result<CaseScene> makeScene(const BenchCase& c, const RenderOptions& options) {
  CaseScene out;
  generators::TrisStats realized;
  if (c.generator == generators::Generator::tris) {
    generators::TrisParams t = c.tris;
    if (t.count < 0 || t.count > 20'000'000 || !(t.area > 0 && t.area <= 1e7) || !(t.depth >= 0))
      return Error{"", "", "tris: count must be 0…2e7, area in (0, 1e7] px, depth ≥ 0"};
    t.width = options.width;
    t.height = options.height;
    out.scene = generators::generateTris(t, &realized);
    out.params = {{"count", t.count},
                  {"area", t.area},
                  {"depth", t.depth},
                  {"order", generators::submitOrderName(t.order)},
                  {"seed", t.seed}};
  } else if (c.generator == generators::Generator::layers) {
    generators::LayersParams l = c.layers;
    if (l.layers < 1 || l.layers > 64) return Error{"", "", "layers: D must be 1…64"};
    l.width = options.width;
    l.height = options.height;
    out.scene = generators::generateLayers(l, &realized);
    out.params = {
        {"layers", l.layers}, {"order", generators::submitOrderName(l.order)}, {"seed", l.seed}};
  } else if (c.generator == generators::Generator::grazing) {
    out.scene = generators::generateGrazing(c.grazing);
    out.params = {{"seed", c.grazing.seed}};
    return out;  // no target area or depth complexity to report
  } else if (c.generator == generators::Generator::freeform) {
    generators::FreeFormParams f = c.freeform;
    if (f.count < 0 || f.count > 100000) return Error{"", "", "freeform: objects must be 0…100000"};
    f.width = options.width;
    f.height = options.height;
    out.scene = generators::generateFreeForms(f);
    out.params = {{"objects", f.count}, {"seed", f.seed}};
    return out;
  } else if (c.generator == generators::Generator::freeformOne) {
    out.scene = generators::generateFreeFormOne();
    out.params = {{"objects", 1}, {"perturbations", 6}};
    return out;
  } else if (c.generator == generators::Generator::terrain) {
    Result<scene::Scene> t = generators::generateTerrain(c.terrain);
    if (!t) return t.error();
    out.scene = std::move(t).value();
    out.params = {{"size", c.terrain.size},
                  {"seed", c.terrain.seed},
                  {"interpolation", c.terrain.bicubic ? "bicubic" : "bilinear"}};
    return out;
  } else if (c.generator == generators::Generator::lights) {
    generators::LightsParams l = c.lights;
    l.width = options.width;
    l.height = options.height;
    Result<scene::Scene> made = generators::generateLights(l);
    if (!made) return made.error();
    out.scene = std::move(made).value();
    out.params = {{"lights", out.scene.lightPoints.size()},
                  {"stars", out.scene.stars.stars.size()},
                  {"seed", l.seed},
                  {"layers", 1}};
    return out;
  } else if (c.generator == generators::Generator::city) {
    const generators::CityParams& p = c.city;
    if (p.buildings < 1 || p.buildings > 1000000 || p.trees < 0 || p.trees > 10000000)
      return Error{"", "", "city: buildings must be 1…1e6 and trees 0…1e7"};
    out.scene = generators::generateCity(p);
    out.params = {{"buildings", p.buildings}, {"trees", p.trees}, {"seed", p.seed}};
    return out;
  } else if (c.generator == generators::Generator::volume) {
    const generators::VolumeParams& p = c.volume;
    if (p.size < 8 || p.size > 512) return Error{"", "", "volume: --voxels must be 8…512"};
    out.scene = generators::generateVolume(p);
    out.params = {{"voxels", p.size}, {"opaque", p.opaque},
                  {"precomputed_normals", p.precomputedNormals}, {"shell", p.shell},
                  {"seed", p.seed}};
    return out;
  } else if (c.generator == generators::Generator::none) {
    auto loaded = formats::loadScene(c.file);
    if (!loaded) return loaded.error();
    out.scene = std::move(loaded).value();
    out.params = {{"file", c.file}};
    return out;
  } else {
    return Error{
        "", "",
        fmt::format("generator '{}' is not a bench case", generators::generatorName(c.generator))};
  }
  out.meanArea = realized.meanArea;
  out.depthComplexity = realized.depthComplexity;
  out.params["realized_mean_area"] = realized.meanArea;
  out.params["depth_complexity"] = realized.depthComplexity;
  return out;
}

struct BenchRunner::Impl {
  BenchSettings settings;
  std::unique_ptr<GlRenderer> gl;
  std::string glDescription;
};

BenchRunner::BenchRunner(const BenchSettings& settings) : impl_(std::make_unique<Impl>()) {
  impl_->settings = settings;
}
BenchRunner::~BenchRunner() = default;
const std::string& BenchRunner::referenceDescription() const { return impl_->glDescription; }

Status BenchRunner::startReference() {
  auto gl = GlRenderer::create(impl_->settings.options, impl_->settings.referenceMsaa);
  if (!gl.ok()) return gl.error();
  impl_->gl = std::move(gl).value();
  impl_->glDescription = impl_->gl->description();
  return {};
}

namespace {

// BenchSettings::display: the unwarped view, method (a) and method (b), frame by frame.
Status runDisplayBench(const scene::Scene& sc, const BenchSettings& s, CaseResult& r) {
  if (!sc.channels.empty()) return Error{"", "", "display: the scene's camera view, not channels"};
  const render::DisplaySetup display = render::cylinderDisplay(s.options.width, s.options.height);
  const render::ProjectorSetup& centre = display.projectors[1];
  Renderer unwarped(s.options);
  render::CorrectionRenderer warped(s.options);
  const Result<render::FrameCamera> base = render::chooseCamera(sc, s.options);
  if (!base.ok()) return base.error();
  display::SubFrustumOptions so;
  so.znear = base.value().camera.znear;
  so.zfar = base.value().camera.zfar;
  const auto t0 = Clock::now();
  const display::SubFrustumPlan plan = display::planSubFrusta(centre.table, so);
  const double planMs = msSince(t0);
  // Issue 61: the same cells refitted for an eye moved by a head's motion (2 cm, 1 cm, −1 cm), the
  // screen points kept once (display::refitPlan).
  std::string refit;
  if (display.rig) {
    display::DisplayGeometry g = display.rig->geometry(1);
    const display::PlanScreenPoints points = display::planScreenPoints(plan, centre.table, g);
    g.eye = g.eye + Vec3{0.02f, 0.01f, -0.01f};
    display::RefitStats st;
    display::SubFrustumPlan moved;
    std::vector<double> ms;  // the median of 5
    for (int k = 0; k < 5; ++k) {
      const auto t2 = Clock::now();
      moved = display::refitPlan(plan, points, g, so, &st, &warped.pool());
      ms.push_back(msSince(t2));
    }
    std::sort(ms.begin(), ms.end());
    refit = fmt::format(
        "; refitted for a moved eye in {:.2f} ms (median of 5): {} cells, {} planned again, "
        "residual ≤ {:.3f} px at the checks",
        ms[2], moved.cells.size(), st.replanned, moved.maxResidualPixels);
  }
  RendererRun flat{"synthvis", "synthvis, the unwarped view", {}, 0, 0, 0, {}, {}, {}};
  RendererRun a{"subfrusta",
                fmt::format("synthvis through {} sub-frusta (residual ≤ {:.3f} px; the plan took "
                            "{:.1f} ms, once{})",
                            plan.cells.size(), plan.maxResidualPixels, planMs, refit),
                {},
                0,
                0,
                0,
                {},
                {},
                {}};
  const auto t1 = Clock::now();
  const Result<display::ResampleWarp> warp = render::resampleWarpOf(centre.table);
  if (!warp.ok()) return warp.error();
  const double warpMs = msSince(t1);
  RendererRun b{"resampled",
                fmt::format("synthvis, a flat view of {} × {} with margin resampled bilinear (the "
                            "warp took {:.1f} ms, once)",
                            warp.value().view.width, warp.value().view.height, warpMs),
                {}, 0, 0, 0, {}, {}, {}};
  render::DisplayFrame frameA, frameB;
  for (int i = 0; i < s.warmup + s.frames; ++i) {
    auto t = Clock::now();
    if (Status st = unwarped.render(sc, flat.image, &flat.stats); !st) return st;
    if (i >= s.warmup) flat.frameMs.push_back(msSince(t));
    for (auto [run, correction, frame] :
         {std::tuple{&a, RenderOptions::Correction::subFrusta, &frameA},
          std::tuple{&b, RenderOptions::Correction::bilinear, &frameB}}) {
      render::CorrectedView view;
      view.table = &centre.table;
      view.plan = &plan;
      view.warp = &warp.value();
      view.eye = display.eye;
      view.correction = correction;
      frame->linear.resize(1);
      frame->images.resize(1);
      run->stats = {};
      DisplayStats cs;
      t = Clock::now();
      if (Status st = render::renderCorrected(warped, sc, s.options, base.value(), view,
                                              frame->linear[0], run->stats, cs, &run->image, false);
          !st)
        return st;
      if (i >= s.warmup) run->frameMs.push_back(msSince(t));
    }
  }
  for (RendererRun* run : {&flat, &a, &b}) {
    finish(*run);
    r.runs.push_back(std::move(*run));
  }
  r.psnrDb = psnr(r.runs[1].image, r.runs[2].image);  // method (a) against method (b)
  r.params["display"] = "cylinder3, centre projector";
  r.params["subfrusta_cells"] = plan.cells.size();
  return {};
}

// BenchSettings::pipelines: the tile pipeline under priority masking and the segment pipeline,
// frame by frame.
Status runPipelinesBench(const scene::Scene& sc, const BenchSettings& s, CaseResult& r) {
  if (!sc.channels.empty()) return Error{"", "", "segments: the scene's camera view, not channels"};
  RenderOptions tileOptions = s.options, segmentOptions = s.options;
  tileOptions.hsr = RenderOptions::Hsr::priority;
  tileOptions.pipeline = RenderOptions::Pipeline::tiles;
  tileOptions.segmentChannel = {};
  segmentOptions.pipeline = RenderOptions::Pipeline::segments;
  if (Status st = validate(segmentOptions); !st) return st;
  Renderer tiles(tileOptions), segments(segmentOptions);
  RendererRun a{"synthvis", "synthvis, the tile pipeline under priority masking",
                {}, 0, 0, 0, {}, {}, {}};
  RendererRun b{"segments", "synthvis, seed 002's segment pipeline", {}, 0, 0, 0, {}, {}, {}};
  for (int i = 0; i < s.warmup + s.frames; ++i) {
    for (auto [run, renderer] : {std::pair{&a, &tiles}, std::pair{&b, &segments}}) {
      run->stats = {};
      const auto t = Clock::now();
      if (Status st = renderer->render(sc, run->image, &run->stats); !st) return st;
      if (i >= s.warmup) run->frameMs.push_back(msSince(t));
    }
  }
  for (RendererRun* run : {&a, &b}) {
    finish(*run);
    r.runs.push_back(std::move(*run));
  }
  const FrameStats& st = r.runs[1].stats;
  r.psnrDb = psnr(r.runs[0].image, r.runs[1].image);
  r.params["pipeline"] = "segments against tiles (priority masking)";
  r.params["segments_per_frame"] = st.segments;
  r.params["runs_per_frame"] = st.segmentRuns;
  r.params["segments_per_second"] = double(st.segments) / (r.runs[1].medianMs / 1000);
  // Overload protection (RenderOptions::SegmentChannel): the lines repeated in the last frame,
  // and their share of the frame's lines.
  r.params["segment_words_per_line"] = s.options.segmentChannel.wordsPerLine;
  r.params["repeated_lines"] = st.repeatedLines;
  r.params["repeated_share"] = double(st.repeatedLines) / double(s.options.height);
  return {};
}

// The case's scene as the settings show it: shaded as they say, in their channels, and for VTK
// its volumes alone (VTK draws nothing else: in both renderers they are timed without what
// surrounds them, the row's "volumes_alone" says so).
Result<CaseScene> benchScene(const BenchCase& c, const BenchSettings& s, bool gl) {
  BenchCase shaded = c;
  shaded.tris.textured = shaded.layers.textured = s.textured;
  shaded.tris.fog = shaded.layers.fog = shaded.grazing.fog = s.fog;
  auto made = makeScene(shaded, s.options);
  if (!made.ok()) return made.error();
  if (s.channels > 0 && made.value().scene.channels.empty()) {
    made.value().scene.channels =
        scene::arcChannels(s.channels, s.arcDegrees, s.options.width, s.options.height);
    if (made.value().scene.channels.empty())
      return Error{"", "",
                   fmt::format("--channels {}: must be 1…{}", s.channels, scene::kMaxChannels)};
  }
  if (!made.value().scene.channels.empty() && gl)
    return Error{"", "",
                 "channels: the gl reference draws one view only (use --renderer synthvis)"};
  if (s.vtk && !made.value().scene.volumes.empty() && !besideVolumes(made.value().scene).empty()) {
    made.value().params["volumes_alone"] = true;
    made.value().scene = volumesAlone(made.value().scene);
  }
  return made;
}

// A renderer's run before its first frame.
RendererRun startedRun(std::string renderer, std::string description) {
  RendererRun run;
  run.renderer = std::move(renderer);
  run.description = std::move(description);
  return run;
}

// One comparison of BenchSettings: synthvis as asked against its reference — synthvis another
// way (free forms marched or tessellated, every instance at full detail), VTK or GL — timed
// frame by frame.
struct Comparison {
  Comparison(const BenchSettings& settings, GlRenderer* glRenderer)
      : s(settings), gl(glRenderer), renderer(settings.options) {}
  const BenchSettings& s;
  GlRenderer* gl;  // the gl reference, when started
  Renderer renderer;
  std::optional<Renderer> marcher;          // synthvis as the reference
  std::unique_ptr<VtkVolumeRenderer> vtk;   // VTK as the reference
  std::optional<scene::Scene> tessellated;  // free forms and terrain as triangles
  std::optional<RendererRun> ours, ref;
  std::vector<Image> oursImages, refImages;  // with channels: each channel's last frame

  // The scene the polygon references draw.
  const scene::Scene& polygons(const scene::Scene& sc) const {
    return tessellated ? *tessellated : sc;
  }
  // Synthvis another way: its reference is itself, not VTK or GL.
  bool selfReference() const { return s.sphereTrace || s.tessellated || s.fullDetail; }
};

// The renderers the comparison needs beside synthvis, or why the case cannot be compared.
Status startRenderers(Comparison& k, const scene::Scene& sc, CaseResult& r) {
  const BenchSettings& s = k.s;
  RenderOptions marchOptions = s.options;
  marchOptions.freeFormMethod = RenderOptions::FreeFormMethod::march;
  RenderOptions fullDetailOptions = s.options;
  fullDetailOptions.cullInstances = fullDetailOptions.lod = false;
  if (k.selfReference())
    k.marcher.emplace(s.sphereTrace ? marchOptions : s.fullDetail ? fullDetailOptions : s.options);
  // Volumes have no polygon form: a gl row would leave them out, and its ratio and PSNR would
  // compare different pictures. Their baseline is VTK's ray caster (issue 33).
  if (s.vtk && !sc.volumes.empty()) {
    auto v = VtkVolumeRenderer::create(sc, s.options);
    if (!v.ok()) return v.error();
    k.vtk = std::move(v).value();
  } else if (k.gl && !sc.volumes.empty()) {
    return Error{"", "", fmt::format("the gl reference does not draw volumes ({} in the scene)",
                                     sc.volumes.size())};
  } else if (s.vtk && !s.synthvis) {
    return Error{"", "", "the vtk reference draws volume scenes only"};
  }
  // Free forms as triangles, for the polygon baseline and for the gl reference.
  if ((!sc.freeForms.empty() || !sc.terrains.empty()) && (s.tessellated || k.gl)) {
    auto t = tessellatedScene(sc, s.options);
    if (!t.ok()) return t.error();
    k.tessellated = std::move(t).value();
    r.params["tessellated_triangles"] = k.tessellated->triangleCount();
  }
  return {};
}

// The runs to time: synthvis's when asked, and the reference's (the gl reference loads the
// scene here, untimed).
Status startRuns(Comparison& k, const scene::Scene& sc, const std::string& glDescription) {
  const BenchSettings& s = k.s;
  if (s.synthvis) k.ours = startedRun("synthvis", "synthvis");
  if (s.sphereTrace) {
    k.ref = startedRun("sphere-trace", fmt::format("synthvis, free forms marched in {} steps",
                                                   s.options.marchSteps));
  } else if (s.tessellated) {
    k.ref = startedRun("tessellated", fmt::format("synthvis, free forms as {} triangles",
                                                  k.polygons(sc).triangleCount()));
  } else if (s.fullDetail) {
    k.ref = startedRun(
        "full-detail",
        fmt::format("synthvis, every instance at full detail ({} triangles)", sc.triangleCount()));
  } else if (k.vtk) {
    k.ref = startedRun("vtk", k.vtk->description());
  } else if (k.gl) {
    if (Status st = k.gl->load(k.polygons(sc)); !st) return st;
    k.ref = startedRun("gl", glDescription);
  }
  return {};
}

// One frame: the classic view, or every channel (SPEC §9), timed as one.
Status renderFrame(Renderer& with, const scene::Scene& scene, RendererRun& run,
                   std::vector<Image>& images) {
  if (scene.channels.empty()) return with.render(scene, run.image, &run.stats);
  if (Status st = with.renderChannels(scene, images, &run.channelStats); !st) return st;
  run.stats = run.channelStats[0];
  return {};
}

// A/B, frame by frame: synthvis's frame, then the reference's; the warm-up frames not kept.
Status timeFrames(Comparison& k, const scene::Scene& sc) {
  const BenchSettings& s = k.s;
  for (int i = 0; i < s.warmup + s.frames; ++i) {
    if (k.ours) {
      const auto t0 = Clock::now();
      if (Status st = renderFrame(k.renderer, sc, *k.ours, k.oursImages); !st) return st;
      const double ms = msSince(t0);
      if (i >= s.warmup) k.ours->frameMs.push_back(ms);
    }
    if (k.ref && k.selfReference()) {
      const auto t0 = Clock::now();
      if (Status st = renderFrame(*k.marcher, s.sphereTrace || s.fullDetail ? sc : k.polygons(sc),
                                  *k.ref, k.refImages);
          !st)
        return st;
      const double ms = msSince(t0);
      if (i >= s.warmup) k.ref->frameMs.push_back(ms);
    } else if (k.ref && k.vtk) {
      const Result<double> ms = k.vtk->render();  // VTK's own render call, timed by the script
      if (!ms.ok()) return ms.error();
      if (i >= s.warmup) k.ref->frameMs.push_back(ms.value());
    } else if (k.ref) {
      const auto t0 = Clock::now();
      if (Status st = k.gl->render(); !st) return st;
      if (s.referenceReadback)
        if (Status st = k.gl->readImage(k.ref->image); !st) return st;
      const double ms = msSince(t0);
      if (i >= s.warmup) k.ref->frameMs.push_back(ms);
    }
  }
  return {};
}

// The timed runs into the case's result, synthvis's first, with their last images (the
// reference's read back untimed) and the PSNR between them.
Status collectRuns(Comparison& k, CaseResult& r) {
  if (k.ours) {
    finish(*k.ours);
    if (!k.ours->channelStats.empty()) k.ours->image = mosaic(k.oursImages);
    r.runs.push_back(std::move(*k.ours));
  }
  if (k.ref) {
    finish(*k.ref);
    if (!k.ref->channelStats.empty()) k.ref->image = mosaic(k.refImages);
    if (k.vtk) {
      if (Status st = k.vtk->readImage(k.ref->image); !st) return st;
    } else if (!k.selfReference()) {
      if (Status st = k.gl->readImage(k.ref->image); !st) return st;
    }
    if (!r.runs.empty()) r.psnrDb = psnr(r.runs[0].image, k.ref->image);
    r.runs.push_back(std::move(*k.ref));
  }
  return {};
}

}  // namespace

Result<CaseResult> BenchRunner::run(const BenchCase& c) {
  const BenchSettings& s = impl_->settings;
  if (s.frames < 1 || s.frames > 100000 || s.warmup < 0 || s.warmup > 100000)
    return Error{"", "", "frames must be 1…100000 and warmup 0…100000"};
  auto made = benchScene(c, s, impl_->gl != nullptr);
  if (!made.ok()) return made.error();
  const scene::Scene& sc = made.value().scene;

  CaseResult r;
  r.name = c.name;
  r.params = made.value().params;
  r.triangles = sc.triangleCount();
  r.meanArea = made.value().meanArea;
  r.depthComplexity = made.value().depthComplexity;
  if (s.display) {
    if (impl_->gl || s.vtk)
      return Error{"", "", "display: the warped views are measured against synthvis unwarped"};
    if (Status st = runDisplayBench(sc, s, r); !st) return st.error();
    return r;
  }
  if (s.pipelines) {
    if (impl_->gl || s.vtk)
      return Error{"", "", "segments: the segment pipeline is measured against the tile pipeline"};
    if (Status st = runPipelinesBench(sc, s, r); !st) return st.error();
    return r;
  }
  Comparison k(s, impl_->gl.get());
  if (Status st = startRenderers(k, sc, r); !st) return st.error();
  if (Status st = startRuns(k, sc, impl_->glDescription); !st) return st.error();
  if (Status st = timeFrames(k, sc); !st) return st.error();
  if (Status st = collectRuns(k, r); !st) return st.error();
  return r;
}

namespace {
// Pixels drawn per frame: the generator's realized area, or for files the fragments synthvis
// counted (the same triangles' covered pixel centres).
double pixelsOf(const CaseResult& r) {
  if (r.meanArea > 0) return r.meanArea * double(r.triangles);
  for (const RendererRun& run : r.runs)
    if (run.renderer == "synthvis") {
      if (run.channelStats.empty()) return double(run.stats.fragments);
      double sum = 0;
      for (const FrameStats& c : run.channelStats) sum += double(c.fragments);
      return sum;
    }
  return 0;
}
}  // namespace

std::string simdTarget() {
  const std::vector<int64_t> targets = hwy::SupportedAndGeneratedTargets();
  return targets.empty() ? "none" : hwy::TargetName(targets.front());
}

double psnr(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height || a.rgb.size() != b.rgb.size() || a.rgb.empty())
    return 0;
  double sum = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    const double d = double(a.rgb[i]) - double(b.rgb[i]);
    sum += d * d;
  }
  if (sum == 0) return std::numeric_limits<double>::infinity();
  const double mse = sum / double(a.rgb.size());
  return 10 * std::log10(255.0 * 255.0 / mse);
}

nlohmann::json jsonRows(const CaseResult& r, const BenchSettings& s) {
  nlohmann::json rows = nlohmann::json::array();
  for (const RendererRun& run : r.runs) {
    nlohmann::json row = r.params;
    const double pixels = pixelsOf(r);
    row.update(
        {{"scene", r.name},
         {"renderer", run.renderer},
         {"renderer_description", run.description},
         {"width", s.options.width},
         {"height", s.options.height},
         {"threads", s.options.threads},
         {"frames", s.frames},
         {"warmup", s.warmup},
         {"shade", s.textured ? "textured" : "gouraud"},
         {"fog", s.fog},
         {"hsr", run.renderer == "synthvis" ? hsrName(s.options.hsr)
                 : run.renderer == "vtk"    ? "ray-cast"
                                            : "zbuffer"},
         {"texture_filter", scene::textureFilterName(s.options.textureFilter)},
         {"aa", run.renderer == "synthvis" ? s.options.samples
                : run.renderer == "vtk"    ? 1
                                           : std::max(1, s.referenceMsaa)},
         {"filter", s.options.filter == RenderOptions::Filter::tent3 ? "tent3" : "box"},
         {"readback_timed", run.renderer == "synthvis" || s.referenceReadback},
         {"median_ms", run.medianMs},
         {"min_ms", run.minMs},
         {"max_ms", run.maxMs},
         {"frame_ms", run.frameMs},
         {"triangles", r.triangles},
         {"mtri_per_s", run.medianMs > 0 ? double(r.triangles) / run.medianMs / 1e3 : 0},
         {"mpix_per_s", run.medianMs > 0 ? pixels / run.medianMs / 1e3 : 0}});
    if (run.renderer == "synthvis") {
      row["simd"] = simdTarget();
      uint64_t drawn = run.stats.drawn;
      if (!run.channelStats.empty()) {
        drawn = 0;
        for (const FrameStats& c : run.channelStats) drawn += c.drawn;
      }
      row["triangles_drawn"] = drawn;  // over all channels
    }
    // Views in one frame (SPEC §9): 1 for the classic view; width and height are each channel's.
    row["channels"] = run.channelStats.empty() ? size_t(1) : run.channelStats.size();
    if (r.runs.size() > 1)
      row["psnr_db"] = std::isinf(r.psnrDb) ? nlohmann::json(999.0) : nlohmann::json(r.psnrDb);
    rows.push_back(row);
  }
  return rows;
}

std::string summaryLine(const CaseResult& r) {
  const double pixels = pixelsOf(r);
  std::string line = fmt::format("{:<22} {:>9} tris", r.name, r.triangles);
  for (const RendererRun& run : r.runs)
    line +=
        fmt::format("  {} {:8.2f} ms ({:6.2f} Mtri/s, {:5.0f} Mpix/s)", run.renderer, run.medianMs,
                    double(r.triangles) / run.medianMs / 1e3, pixels / run.medianMs / 1e3);
  if (r.runs.size() > 1)
    line += fmt::format(
        "  ratio {:5.2f}x  psnr {}", r.runs[1].medianMs / r.runs[0].medianMs,
        std::isinf(r.psnrDb) ? std::string("identical") : fmt::format("{:.1f} dB", r.psnrDb));
  for (size_t k = 2; k < r.runs.size(); ++k)
    line += fmt::format("  {} ratio {:5.2f}x", r.runs[k].renderer,
                        r.runs[k].medianMs / r.runs[0].medianMs);
  return line;
}

std::string repeatSummaryLine(const std::vector<CaseResult>& repeats, size_t& middle) {
  auto key = [&](size_t k) {
    const auto& runs = repeats[k].runs;
    return runs.size() > 1 ? runs[1].medianMs / runs[0].medianMs : runs[0].medianMs;
  };
  std::vector<size_t> order(repeats.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](size_t x, size_t y) { return key(x) < key(y); });
  middle = order[(order.size() - 1) / 2];
  auto medianAndRange = [](const std::vector<double>& v, const char* unit) {
    const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
    return fmt::format("{:.2f}{} ({:.2f}–{:.2f})", median(v), unit, *lo, *hi);
  };
  std::string line = fmt::format("median of {} repeats:", repeats.size());
  for (size_t r = 0; r < repeats[0].runs.size(); ++r) {
    std::vector<double> ms;
    for (const CaseResult& c : repeats) ms.push_back(c.runs[r].medianMs);
    line += fmt::format("  {} {}", repeats[0].runs[r].renderer, medianAndRange(ms, " ms"));
  }
  if (repeats[0].runs.size() > 1) {
    std::vector<double> ratio;
    for (size_t k = 0; k < repeats.size(); ++k) ratio.push_back(key(k));
    line += "  ratio " + medianAndRange(ratio, "x");
  }
  return line;
}

namespace {

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}

// Horizontal bars: reference time / synthvis time per case, with a line at 1×.
std::string ratioSvg(const std::vector<CaseResult>& results) {
  const int rowH = 26, left = 190, width = 720, top = 40;
  double maxRatio = 1;
  for (const auto& r : results)
    if (r.runs.size() > 1) maxRatio = std::max(maxRatio, r.runs[1].medianMs / r.runs[0].medianMs);
  maxRatio = std::ceil(maxRatio);
  const int height = top + rowH * int(results.size()) + 40;
  const double scale = (width - left - 60) / maxRatio;
  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" "
      "font-family=\"sans-serif\" "
      "font-size=\"12\">\n<text x=\"10\" y=\"22\" font-size=\"15\">Speed-up of synthvis over the "
      "gl "
      "reference (median ms/frame of gl ÷ synthvis)</text>\n",
      width, height);
  for (int k = 0; k <= int(maxRatio); ++k) {
    const double x = left + k * scale;
    svg += fmt::format(
        "<line x1=\"{0:.1f}\" y1=\"{1}\" x2=\"{0:.1f}\" y2=\"{2}\" stroke=\"{3}\"/>"
        "<text x=\"{0:.1f}\" y=\"{4}\" text-anchor=\"middle\">{5}×</text>\n",
        x, top - 4, height - 30, k == 1 ? "#c33" : "#ddd", height - 14, k);
  }
  for (size_t i = 0; i < results.size(); ++i) {
    const auto& r = results[i];
    const int y = top + rowH * int(i);
    svg += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"end\">{}</text>\n", left - 8,
                       y + rowH / 2 + 4, escape(r.name));
    if (r.runs.size() < 2) continue;
    const double ratio = r.runs[1].medianMs / r.runs[0].medianMs;
    svg += fmt::format(
        "<rect x=\"{}\" y=\"{}\" width=\"{:.1f}\" height=\"{}\" fill=\"#3a6ea5\"/>"
        "<text x=\"{:.1f}\" y=\"{}\">{:.2f}×</text>\n",
        left, y + 4, ratio * scale, rowH - 8, left + ratio * scale + 4, y + rowH / 2 + 4, ratio);
  }
  return svg + "</svg>\n";
}

// ms/frame against a case property (log-log), one series per renderer.
std::string timeSvg(const std::vector<CaseResult>& results, const std::string& title,
                    const std::string& xLabel, double (*xOf)(const CaseResult&)) {
  const int width = 520, height = 350, left = 60, right = 45, top = 60, bottom = 50;
  double x0 = std::numeric_limits<double>::max(), x1 = 0, y0 = x0, y1 = 0;
  for (const auto& r : results) {
    const double x = xOf(r);
    if (!(x > 0)) continue;
    x0 = std::min(x0, x);
    x1 = std::max(x1, x);
    for (const auto& run : r.runs) {
      y0 = std::min(y0, run.medianMs);
      y1 = std::max(y1, run.medianMs);
    }
  }
  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" "
      "font-family=\"sans-serif\" "
      "font-size=\"12\">\n<text x=\"10\" y=\"22\" font-size=\"15\">{}</text>\n",
      width, height, escape(title));
  if (x1 <= 0) return svg + "<text x=\"60\" y=\"120\">no cases</text></svg>\n";
  const double lx0 = std::floor(std::log10(x0)), lx1 = std::max(lx0 + 1, std::ceil(std::log10(x1)));
  const double ly0 = std::floor(std::log10(y0)), ly1 = std::max(ly0 + 1, std::ceil(std::log10(y1)));
  auto px = [&](double x) {
    return left + (std::log10(x) - lx0) / (lx1 - lx0) * (width - left - right);
  };
  auto py = [&](double y) {
    return height - bottom - (std::log10(y) - ly0) / (ly1 - ly0) * (height - top - bottom);
  };
  for (double e = lx0; e <= lx1; ++e)
    svg += fmt::format(
        "<line x1=\"{0:.1f}\" y1=\"{1}\" x2=\"{0:.1f}\" y2=\"{2}\" stroke=\"#ddd\"/>"
        "<text x=\"{0:.1f}\" y=\"{3}\" text-anchor=\"middle\">{4:g}</text>\n",
        px(std::pow(10, e)), top, height - bottom, height - bottom + 16, std::pow(10, e));
  for (double e = ly0; e <= ly1; ++e)
    svg += fmt::format(
        "<line x1=\"{0}\" y1=\"{1:.1f}\" x2=\"{2}\" y2=\"{1:.1f}\" stroke=\"#ddd\"/>"
        "<text x=\"{3}\" y=\"{4:.1f}\" text-anchor=\"end\">{5:g} ms</text>\n",
        left, py(std::pow(10, e)), width - right, left - 4, py(std::pow(10, e)) + 4,
        std::pow(10, e));
  svg += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n",
                     (left + width - right) / 2, height - 12, escape(xLabel));
  const char* colours[2] = {"#3a6ea5", "#d9822b"};
  for (int k = 0; k < 2; ++k) {
    for (const auto& r : results) {
      if (int(r.runs.size()) <= k || !(xOf(r) > 0)) continue;
      svg += fmt::format(
          "<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"4\" fill=\"{}\"><title>{} {}: "
          "{:.2f} ms</title></circle>\n",
          px(xOf(r)), py(r.runs[size_t(k)].medianMs), colours[k], escape(r.name),
          r.runs[size_t(k)].renderer, r.runs[size_t(k)].medianMs);
    }
    svg += fmt::format(
        "<circle cx=\"{}\" cy=\"{}\" r=\"4\" fill=\"{}\"/><text x=\"{}\" y=\"{}\">{}</text>\n",
        left + 10 + 110 * k, top - 22, colours[k], left + 18 + 110 * k, top - 18,
        k == 0 ? "synthvis" : "gl (llvmpipe)");
  }
  return svg + "</svg>\n";
}

// A case name as a file name inside the page's directory: "scenes/a b.json" → "scenes-a-b-json".
std::string fileSlug(const std::string& name) {
  std::string out;
  for (char c : name) {
    const bool keep = std::isalnum(static_cast<unsigned char>(c)) || c == '_';
    if (keep)
      out += c;
    else if (!out.empty() && out.back() != '-')
      out += '-';
  }
  while (!out.empty() && out.back() == '-') out.pop_back();
  return out.empty() ? "scene" : out;
}

Status writeText(const std::filesystem::path& p, const std::string& text) {
  return core::writeFile(p.string(), {text});
}

}  // namespace

Status writeHtml(const std::string& dir, const std::vector<CaseResult>& results,
                 const BenchSettings& s, const std::string& referenceDescription) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return Error{dir, "", "cannot create the directory: " + ec.message()};
  const fs::path d(dir);
  std::vector<CaseResult> tris, layers;
  for (const auto& r : results) {
    if (r.params.contains("count")) tris.push_back(r);
    if (r.params.contains("layers")) layers.push_back(r);
  }
  if (Status st = writeText(d / "ratio.svg", ratioSvg(results)); !st) return st;
  auto byTriangles = [](const CaseResult& r) { return double(r.triangles); };
  auto byArea = [](const CaseResult& r) { return r.meanArea; };
  auto byDepth = [](const CaseResult& r) { return r.depthComplexity; };
  if (Status st =
          writeText(d / "time-triangles.svg",
                    timeSvg(tris, "tris: ms/frame vs triangle count", "triangles", byTriangles));
      !st)
    return st;
  if (Status st =
          writeText(d / "time-area.svg",
                    timeSvg(tris, "tris: ms/frame vs mean triangle area", "mean area, px", byArea));
      !st)
    return st;
  if (Status st = writeText(
          d / "time-depth.svg",
          timeSvg(layers, "layers: ms/frame vs depth complexity", "depth complexity", byDepth));
      !st)
    return st;

  std::string html = fmt::format(
      "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>synthvis bench</title>\n"
      "<style>body{{font-family:sans-serif;margin:2em}}table{{border-collapse:collapse}}"
      "td,th{{border:1px solid #ccc;padding:3px "
      "8px;text-align:right}}td:first-child{{text-align:left}}"
      "img{{max-width:480px;border:1px solid "
      "#ccc}}figure{{display:inline-block;margin:4px}}</style>"
      "</head><body>\n<h1>synthvis bench</h1>\n<p>{}×{}, {} threads, {} timed frames after {} "
      "warm-up, "
      "synthvis and the reference alternating frame by frame. Reference: {}.</p>\n",
      s.options.width, s.options.height, s.options.threads, s.frames, s.warmup,
      escape(referenceDescription.empty() ? std::string("not run") : referenceDescription));
  html +=
      "<p><img src=\"ratio.svg\" style=\"max-width:none;border:0\"></p>\n<p>"
      "<img src=\"time-triangles.svg\" style=\"border:0\"><img src=\"time-area.svg\" "
      "style=\"border:0\">"
      "<img src=\"time-depth.svg\" style=\"border:0\"></p>\n";
  html +=
      "<table><tr><th>scene</th><th>triangles</th><th>mean area px</th><th>depth complexity</th>"
      "<th>synthvis ms</th><th>gl ms</th><th>ratio</th><th>synthvis Mtri/s</th>"
      "<th>synthvis Mpix/s</th><th>PSNR dB</th></tr>\n";
  for (const auto& r : results) {
    const RendererRun* ours = nullptr;
    const RendererRun* gl = nullptr;
    for (const RendererRun& run : r.runs) (run.renderer == "gl" ? gl : ours) = &run;
    auto ms = [](const RendererRun* run) {
      return run ? fmt::format("{:.2f}", run->medianMs) : std::string("–");
    };
    auto rate = [&](double work) {
      return ours ? fmt::format("{:.2f}", work / ours->medianMs / 1e3) : std::string("–");
    };
    html += fmt::format(
        "<tr><td>{}</td><td>{}</td><td>{:.1f}</td><td>{:.2f}</td><td>{}</td><td>{}</td><td>{}</td>"
        "<td>{}</td><td>{}</td><td>{}</td></tr>\n",
        escape(r.name), r.triangles, r.meanArea, r.depthComplexity, ms(ours), ms(gl),
        ours && gl ? fmt::format("{:.2f}×", gl->medianMs / ours->medianMs) : "–",
        rate(double(r.triangles)), rate(pixelsOf(r)),
        !(ours && gl)          ? "–"
        : std::isinf(r.psnrDb) ? "identical"
                               : fmt::format("{:.1f}", r.psnrDb));
  }
  html += "</table>\n<h2>Images</h2>\n";
  for (const auto& r : results) {
    html += fmt::format("<h3>{}</h3>\n", escape(r.name));
    for (const auto& run : r.runs) {
      const std::string file = fmt::format("{}-{}.png", fileSlug(r.name), run.renderer);
      if (Status st = writePng(run.image, (d / file).string()); !st) return st;
      html +=
          fmt::format("<figure><img src=\"{}\"><figcaption>{} — {:.2f} ms</figcaption></figure>\n",
                      escape(file), escape(run.renderer == "gl" ? run.description : run.renderer),
                      run.medianMs);
    }
  }
  html += "</body></html>\n";
  return writeText(d / "index.html", html);
}

}  // namespace sv::reference
