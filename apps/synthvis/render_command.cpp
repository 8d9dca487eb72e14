// `synthvis render [SCENE] -o out.png …`: a frame to an image — the classic view, the scene's
// display channels (SPEC §9) or a curved-screen display's projectors (docs/display.md).
#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <optional>

#include "cli.h"
#include "synthvis/display.h"
#include "synthvis/image.h"

namespace sv::cli {
namespace {

struct RenderArgs {
  std::string scene;
  std::string output = "out.png";
  std::string debugView;
  std::string filter = "box";
  std::string textureFilter = "trilinear";
  std::string hsr = "zbuffer";
  std::string pipeline = "tiles";
  std::string freeform = "raycast";
  std::string terrainFilter = "scene";
  bool noCull = false;
  bool noInstanceCull = false;
  // Display channels (SPEC §9): N abutting channels in an arc of `arc` degrees (0: N times the
  // camera's horizontal field of view) for a scene without channels of its own; the mosaic file.
  int channels = 0;
  float arc = 0;
  std::string mosaic;
  std::optional<double> time;  // the scene's simulation time, seconds (light points' blinking)
  // A curved-screen display (issue 34, docs/display.md): "cylinder3" (the demo rig, projectors of
  // --width × --height) or an MPCDI file; the correction; the simulated viewer's panorama; the rig
  // written as MPCDI.
  std::string display;
  std::string correction = "subfrusta";
  std::string viewer;
  std::string writeMpcdi;
  RenderOptions options;
};

// --channels N [--arc DEG]: N channels abutting in an arc around the scene camera's view, each
// --width × --height with square pixels; without --arc, N times the camera's horizontal field of
// view (so each channel sees what the camera alone would, side by side).
Status addArcChannels(scene::Scene& scene, const RenderOptions& o, int n, float arc) {
  if (arc != 0 && n == 0) return Error{"", "", "--arc needs --channels"};
  if (n == 0) return {};
  if (!scene.channels.empty())
    return Error{
        "", "",
        fmt::format("--channels: the scene has {} channels of its own", scene.channels.size())};
  if (n < 1 || n > int(scene::kMaxChannels))
    return Error{"", "", fmt::format("--channels {}: must be 1…{}", n, scene::kMaxChannels)};
  if (arc == 0) {
    const scene::Camera camera =
        o.camera < int(scene.cameras.size()) ? scene.cameras[size_t(o.camera)] : scene::Camera{};
    const double halfY = camera.yfovDegrees * std::numbers::pi / 360;
    arc = float(n * 360 / std::numbers::pi * std::atan(std::tan(halfY) * o.width / o.height));
  }
  if (!(arc > 0 && arc < 180.0f * float(n)))
    return Error{"", "",
                 fmt::format("--arc {}: must be more than 0 and less than 180 a channel", arc)};
  scene.channels = scene::arcChannels(n, arc, o.width, o.height);
  return {};
}

// A frame whose every triangle was culled for facing away (single-sided materials seen from
// behind) is an empty picture that says why.
void warnIfAllFacedAway(const FrameStats& stats, const std::string& image) {
  if (stats.drawn == 0 && stats.culledFacing > 0)
    fmt::print(stderr,
               "synthvis: warning: {}: every triangle faced away from the camera and was culled "
               "(its materials are single-sided; --no-cull draws back faces)\n",
               image);
}

// A scene with display channels (SPEC §9): all of them in one call; OUT-<name>.png each (the
// channel's index for an unnamed one), a statistics line each, and the mosaic if asked for.
int renderChannels(const RenderArgs& a, const scene::Scene& scene, Renderer& renderer) {
  std::vector<Image> images;
  std::vector<FrameStats> stats;
  if (Status s = renderer.renderChannels(scene, images, &stats); !s) {
    Error e = s.error();
    if (e.file.empty()) e.file = a.scene.empty() ? "<demo scene>" : a.scene;
    return fail(e);
  }
  double totalMs = 0;
  for (size_t i = 0; i < images.size(); ++i) {
    const scene::Channel& c = scene.channels[i];
    const std::string path = withSuffix(a.output, c.name.empty() ? std::to_string(i) : c.name);
    if (Status s = writeImage(images[i], path); !s) return fail(s.error());
    fmt::print("{}: {}x{} | {}\n", path, images[i].width, images[i].height, stats[i].summary());
    warnIfAllFacedAway(stats[i], path);
    totalMs += stats[i].totalMs;
  }
  fmt::print("frame: {} channels, {:.2f} ms\n", images.size(), totalMs);
  if (!a.mosaic.empty()) {
    if (Status s = writeImage(mosaic(images), a.mosaic); !s) return fail(s.error());
    fmt::print("{}: the {} channels side by side\n", a.mosaic, images.size());
  }
  return 0;
}

// --display: every projector's pre-distorted, blended frame as OUT-<projector>.png with a line
// each, the viewer's panorama and the rig's MPCDI file if asked for.
int renderDisplay(const RenderArgs& a, const scene::Scene& scene, RenderOptions o) {
  const auto correction = parseCorrection(a.correction);
  if (!correction) return fail(correction.error());
  o.correction = correction.value();
  Result<Display> display = a.display == "cylinder3" ? Display::cylinder(o.width, o.height)
                                                     : Display::readMpcdi(a.display);
  if (!display) return fail(display.error());
  if (!a.writeMpcdi.empty()) {
    if (Status s = display->writeMpcdi(a.writeMpcdi); !s) return fail(s.error());
    fmt::print("{}: the display as MPCDI (3d profile, {} regions)\n", a.writeMpcdi,
               display->projectorCount());
  }
  Renderer renderer(o);
  std::vector<Image> images;
  std::vector<FrameStats> stats;
  std::vector<DisplayStats> corrections;
  if (Status s = renderer.renderDisplay(scene, display.value(), images, &stats, &corrections); !s) {
    Error e = s.error();
    if (e.file.empty()) e.file = a.scene.empty() ? "<demo scene>" : a.scene;
    return fail(e);
  }
  double totalMs = 0;
  for (size_t i = 0; i < images.size(); ++i) {
    const std::string path = withSuffix(a.output, display->projectorName(int(i)));
    if (Status s = writeImage(images[i], path); !s) return fail(s.error());
    const DisplayStats& c = corrections[i];
    const std::string how =
        o.correction == RenderOptions::Correction::subFrusta
            ? fmt::format("{} sub-frusta, residual <= {:.3f} px, plan {:.1f} ms", c.cells,
                          c.maxResidualPixels, c.planMs)
            : fmt::format("flat {}x{} resampled {} in {:.1f} ms", c.flatWidth, c.flatHeight,
                          a.correction, c.resampleMs);
    fmt::print("{}: {}x{} | {} | {}\n", path, images[i].width, images[i].height, how,
               stats[i].summary());
    totalMs += stats[i].totalMs;
  }
  fmt::print("frame: {} projectors, {:.2f} ms\n", images.size(), totalMs);
  if (!a.viewer.empty()) {
    auto image = renderer.viewerImage(display.value());
    if (!image) return fail(image.error());
    if (Status s = writeImage(image.value(), a.viewer); !s) return fail(s.error());
    fmt::print("{}: the viewer's view of the screen, azimuth -100 … 100°, elevation -25 … 25°\n",
               a.viewer);
  }
  return 0;
}

int runRender(const RenderArgs& a) {
  RenderOptions o = a.options;
  o.cullBackFaces = !a.noCull;
  o.cullInstances = !a.noInstanceCull;
  auto filter = parseFilter(a.filter);
  if (!filter) return fail(filter.error());
  o.filter = filter.value();
  auto textureFilter = scene::parseTextureFilter(a.textureFilter);
  if (!textureFilter) return fail(textureFilter.error());
  o.textureFilter = textureFilter.value();
  auto hsr = parseHsr(a.hsr);
  if (!hsr) return fail(hsr.error());
  o.hsr = hsr.value();
  auto pipeline = parsePipeline(a.pipeline);
  if (!pipeline) return fail(pipeline.error());
  o.pipeline = pipeline.value();
  if (a.freeform != "raycast" && a.freeform != "march")
    return fail(
        {"", "", fmt::format("unknown free-form method '{}' (raycast or march)", a.freeform)});
  o.freeFormMethod = a.freeform == "march" ? RenderOptions::FreeFormMethod::march
                                           : RenderOptions::FreeFormMethod::raycast;
  auto terrainFilter = parseTerrainFilter(a.terrainFilter);
  if (!terrainFilter) return fail(terrainFilter.error());
  o.terrainFilter = terrainFilter.value();
  if (!a.debugView.empty()) {
    using DebugView = RenderOptions::DebugView;
    if (a.debugView == "overdraw")
      o.debugView = DebugView::overdraw;
    else if (a.debugView == "levels")
      o.debugView = DebugView::levels;
    else if (a.debugView == "occupancy")
      o.debugView = DebugView::occupancy;
    else
      return fail(
          {"", "",
           fmt::format("unknown debug view '{}' (overdraw, levels or occupancy)", a.debugView)});
  }
  if (Status s = validate(o); !s) return fail(s.error());

  auto loaded = loadSceneOrDemo(a.scene);
  if (!loaded) return fail(loaded.error());
  scene::Scene scene = std::move(loaded).value();
  if (a.time) {
    if (!std::isfinite(*a.time)) return fail({"", "", "--time: not a finite number of seconds"});
    scene.time = *a.time;
  }
  if (Status s = addArcChannels(scene, o, a.channels, a.arc); !s) {
    Error e = s.error();
    if (!scene.channels.empty() && !a.scene.empty()) e.file = a.scene;  // its channels conflict
    return fail(e);
  }
  if (!a.display.empty()) {
    if (!scene.channels.empty() || a.channels > 0)
      return fail({"", "", "--display draws the scene camera's view: not with channels"});
    return renderDisplay(a, scene, o);
  }
  if (!a.viewer.empty() || !a.writeMpcdi.empty())
    return fail({"", "", "--viewer and --write-mpcdi need --display"});
  Renderer renderer(o);
  if (!scene.channels.empty()) return renderChannels(a, scene, renderer);
  if (!a.mosaic.empty())
    return fail({"", "", "--mosaic: the scene has no channels (add --channels N)"});
  Image image;
  FrameStats stats;
  if (Status s = renderer.render(scene, image, &stats); !s) {
    Error e = s.error();
    if (e.file.empty()) e.file = a.scene.empty() ? "<demo scene>" : a.scene;
    return fail(e);
  }
  if (Status s = writeImage(image, a.output); !s) return fail(s.error());
  fmt::print("{}: {}x{} | {}\n", a.output, o.width, o.height, stats.summary());
  warnIfAllFacedAway(stats, a.output);
  return 0;
}

void addRenderOptions(CLI::App* render, RenderArgs& r) {
  render->add_option("scene", r.scene,
                     "scene file (.json, .gltf, .glb, .obj); default: built-in demo");
  render->add_option("-o,--output", r.output, "output image (.png or .ppm)")->capture_default_str();
  render->add_option("--width", r.options.width, "image width in pixels")->capture_default_str();
  render->add_option("--height", r.options.height, "image height in pixels")->capture_default_str();
  render->add_option("--threads", r.options.threads, "worker threads (0 = all hardware threads)")
      ->capture_default_str();
  render->add_option("--camera", r.options.camera, "index of the scene camera to use")
      ->capture_default_str();
  render->add_option("--time", r.time,
                     "simulation time in seconds (blinking and sequenced light points, the "
                     "stars' rotation); default: the scene's own");
  render->add_flag("--no-cull", r.noCull, "draw back faces of single-sided materials too");
  render->add_flag("--no-instance-cull", r.noInstanceCull,
                   "transform every instance, also those wholly outside the view");
  render->add_flag(
      "--no-lod", [&r](int64_t) { r.options.lod = false; },
      "draw every instance at full detail (level 0) at every range");
  render->add_flag(
      "--no-merge", [&r](int64_t) { r.options.mergeCells = false; },
      "draw every instance on its own, also where its merged cell would do");
  render
      ->add_option("--lod-scale", r.options.lodScale,
                   "multiplies every level-of-detail range (2: coarser levels at half the "
                   "distance)")
      ->capture_default_str();
  render->add_option("--debug-view", r.debugView,
                     "false-colour diagnostic image: overdraw, levels or occupancy (with --hsr "
                     "priority or hybrid)");
  render
      ->add_option("--supersample", r.options.supersample,
                   "render k×k samples per pixel and average them (1, 2, 4, 8, 16)")
      ->capture_default_str();
  render
      ->add_option("--aa", r.options.samples,
                   "anti-aliasing: samples per pixel, " + sampleCountNames() + " (1: none)")
      ->capture_default_str();
  render->add_option("--filter", r.filter, "resolve filter: box or tent3 (3x3 triangle)")
      ->capture_default_str();
  render
      ->add_option("--hsr", r.hsr,
                   "hidden surfaces: zbuffer, priority (masking; the scene's order is the "
                   "priority, nearest first) or hybrid (masking with depth: any order)")
      ->capture_default_str();
  render
      ->add_option("--pipeline", r.pipeline,
                   "rasterization: tiles (recursive subdivision, masks, masking) or segments "
                   "(seed 002's scan-line segments, priority X-sort into RUN codes; polygons with "
                   "vertex colours, priority order)")
      ->capture_default_str();
  addSegmentChannelOptions(render, r.options);
  render
      ->add_option("--texture-filter", r.textureFilter,
                   "texture sampling for materials that do not choose: point, nearest, tri3, "
                   "bilinear, trilinear3, trilinear or aniso")
      ->capture_default_str();
  render
      ->add_option("--freeform", r.freeform,
                   "free forms: raycast (multi-level ray casting) or march (the fixed-step "
                   "baseline, --march-steps steps of eye depth per ray)")
      ->capture_default_str();
  render->add_option("--march-steps", r.options.marchSteps, "--freeform march: steps per ray")
      ->capture_default_str();
  render
      ->add_option("--volume-window-tolerance", r.options.volumeWindowTolerance,
                   "volumes: the largest difference between a screen window's corner rays for its "
                   "pixels to be interpolated (0: every pixel cast; default: the scene's own)")
      ->check(CLI::Range(0.0f, 1.0f));
  render
      ->add_option("--terrain-filter", r.terrainFilter,
                   "terrain interpolation: scene (each terrain's own), bilinear or bicubic")
      ->capture_default_str();
  render
      ->add_option("--gamma", r.options.gamma,
                   "display gamma G (encoded = linear^(1/G)); default 0 = sRGB")
      ->capture_default_str();
  render->add_option("--channels", r.channels,
                     "display channels: N abutting views from the scene camera, each --width x "
                     "--height, written as OUT-0.png, OUT-1.png, … (for a scene without channels)");
  render->add_option("--arc", r.arc,
                     "--channels: the arc they span, degrees (default: N times the camera's "
                     "horizontal field of view)");
  render->add_option("--mosaic", r.mosaic,
                     "a scene with channels: also write them side by side into this image");
  render->add_option("--display", r.display,
                     "a curved-screen display: cylinder3 (three projectors of --width x --height "
                     "on a cylinder around the eye) or an MPCDI file (3d profile); each "
                     "projector's pre-distorted, edge-blended image is written as OUT-<name>.png");
  render
      ->add_option("--correction", r.correction,
                   "--display: subfrusta (the seeds' sub-frustum projective maps, no "
                   "resampling), or a flat view resampled bilinear or bicubic")
      ->capture_default_str();
  render->add_option("--viewer", r.viewer,
                     "--display cylinder3: write the simulated viewer's view of the screen here");
  render->add_option("--write-mpcdi", r.writeMpcdi,
                     "--display cylinder3: write the rig as an MPCDI file (3d profile) here");
}

}  // namespace

void addRenderCommand(CLI::App& app, Run& run) {
  auto r = std::make_shared<RenderArgs>();
  CLI::App* render = app.add_subcommand("render", "render a scene to an image");
  addRenderOptions(render, *r);
  render->callback([&run, r] { run = [r] { return runRender(*r); }; });
}

}  // namespace sv::cli
