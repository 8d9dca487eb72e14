// synthvis — command-line front end.
//
//   synthvis render [SCENE] -o out.png [--width W] [--height H] [--threads T] [--camera I]
//                   [--channels N [--arc DEG]] [--mosaic FILE]
//                   [--no-cull] [--no-instance-cull] [--no-lod] [--no-merge] [--lod-scale S] [--debug-view overdraw|levels|occupancy] [--gamma G]
//                   [--supersample K] [--aa 1|4|8|16|64] [--filter box|tent3]
//                   [--texture-filter point|nearest|tri3|bilinear|trilinear3|trilinear|aniso]
//                   [--hsr zbuffer|priority|hybrid]
//   synthvis bench SCENE|--suite quick|full [--count N] [--area A] [--depth D] [--layers D]
//                  [--order random|f2b|b2f] [--shade gouraud|textured] [--fog]
//                  [--texture-filter F] [--hsr zbuffer|priority|hybrid] [--width W] [--height H]
//                  [--threads T] [--frames F] [--warmup W] [--seed S] [--aa S] [--gl-aa S]
//                  [--filter box|tent3] [--repeat N] [--channels N [--arc DEG]]
//                  [--renderer synthvis|gl|both] [--gl-readback] [--json FILE] [--html DIR]
//                  [--image FILE]
//   synthvis gen tris|layers|grazing -o scene.glb [--count N] [--area A] [--depth D] [--layers D]
//                [--order O] [--seed S] [--width W] [--height H] [--shade gouraud|textured]
//   synthvis truth [SCENE] -o truth.png [--samples 256] [--width W] [--height H] [--threads T]
//   synthvis truth … [--edges MASK.png]
//   synthvis compare IMAGE.png REFERENCE.png [--edges MASK.png]
//   synthvis ig CONFIG [--output null|png:DIR|y4m:PATH|window[:channels]] [--frames N]
//               [--record FILE.pcap] [--replay FILE.pcap] [--status FILE|-] [--overlay]
//               [--test-pattern grid|bars|wedges] [--as-fast-as-possible] [--no-governor]
//   synthvis host SCRIPT [--ig-port P] [--port P] [--frames N]
//   synthvis prep INPUT|city -o DB.svdb [--no-optimize] [--no-lods] [--lod-levels N]
//                [--reduction R] [--pixel-error P] [--buildings N] [--trees N]
//   (shared BENCH.md defines the scenes and the JSON fields)
//
// Errors print one line, "synthvis: <file>: <problem>", and exit with status 1 (2 for usage).
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>

#include "cluster/cluster.h"
#include "core/files.h"
#include "display/mpcdi.h"
#include "ig/config.h"
#include "ig/host.h"
#include "ig/loop.h"
#include "prep/prep.h"
#include "reference/ground_truth.h"
#include "reference/suite.h"
#include "render/correction.h"
#include "synthvis/formats.h"
#include "synthvis/generators.h"
#include "synthvis/image.h"
#include "synthvis/render.h"
#include "synthvis/scene.h"
#include "synthvis/terrain.h"
#include "terrain/height_field.h"

namespace {

int fail(const sv::Error& e) {
  fmt::print(stderr, "synthvis: {}\n", e.str());
  return 1;
}

// The scene at `path`, or the built-in demo scene when no path is given; what the file holds but
// is not drawn is printed as warnings.
sv::Result<sv::scene::Scene> loadSceneOrDemo(const std::string& path) {
  if (path.empty()) return sv::formats::demoScene();
  sv::Result<sv::scene::Scene> scene = sv::formats::loadScene(path);
  if (scene)
    for (const std::string& w : scene->warnings) fmt::print(stderr, "synthvis: warning: {}\n", w);
  return scene;
}

// --filter box|tent3.
sv::Result<sv::RenderOptions::Filter> parseFilter(const std::string& name) {
  if (name == "box") return sv::RenderOptions::Filter::box;
  if (name == "tent3") return sv::RenderOptions::Filter::tent3;
  return sv::Error{"", "", fmt::format("unknown filter '{}' (box or tent3)", name)};
}

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
  sv::RenderOptions options;
};

// `path` with "-" + `suffix` before its extension: out.png → out-left.png.
std::string withSuffix(const std::string& path, const std::string& suffix) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash))
    return path + "-" + suffix;
  return path.substr(0, dot) + "-" + suffix + path.substr(dot);
}

// --channels N [--arc DEG]: N channels abutting in an arc around the scene camera's view, each
// --width × --height with square pixels; without --arc, N times the camera's horizontal field of
// view (so each channel sees what the camera alone would, side by side).
sv::Status addArcChannels(sv::scene::Scene& scene, const sv::RenderOptions& o, int n, float arc) {
  if (arc != 0 && n == 0) return sv::Error{"", "", "--arc needs --channels"};
  if (n == 0) return {};
  if (!scene.channels.empty())
    return sv::Error{
        "", "",
        fmt::format("--channels: the scene has {} channels of its own", scene.channels.size())};
  if (n < 1 || n > int(sv::scene::kMaxChannels))
    return sv::Error{"", "",
                     fmt::format("--channels {}: must be 1…{}", n, sv::scene::kMaxChannels)};
  if (arc == 0) {
    const sv::scene::Camera camera = o.camera < int(scene.cameras.size())
                                         ? scene.cameras[size_t(o.camera)]
                                         : sv::scene::Camera{};
    const double halfY = camera.yfovDegrees * std::numbers::pi / 360;
    arc = float(n * 360 / std::numbers::pi * std::atan(std::tan(halfY) * o.width / o.height));
  }
  if (!(arc > 0 && arc < 180.0f * float(n)))
    return sv::Error{"", "",
                     fmt::format("--arc {}: must be more than 0 and less than 180 a channel", arc)};
  scene.channels = sv::scene::arcChannels(n, arc, o.width, o.height);
  return {};
}

// A scene with display channels (SPEC §9): all of them in one call; OUT-<name>.png each (the
// channel's index for an unnamed one), a statistics line each, and the mosaic if asked for.
int renderChannels(const RenderArgs& a, const sv::scene::Scene& scene, sv::Renderer& renderer) {
  std::vector<sv::Image> images;
  std::vector<sv::FrameStats> stats;
  if (sv::Status s = renderer.renderChannels(scene, images, &stats); !s) {
    sv::Error e = s.error();
    if (e.file.empty()) e.file = a.scene.empty() ? "<demo scene>" : a.scene;
    return fail(e);
  }
  double totalMs = 0;
  for (size_t i = 0; i < images.size(); ++i) {
    const sv::scene::Channel& c = scene.channels[i];
    const std::string path = withSuffix(a.output, c.name.empty() ? std::to_string(i) : c.name);
    if (sv::Status s = sv::writeImage(images[i], path); !s) return fail(s.error());
    fmt::print("{}: {}x{} | {}\n", path, images[i].width, images[i].height, stats[i].summary());
    totalMs += stats[i].totalMs;
  }
  fmt::print("frame: {} channels, {:.2f} ms\n", images.size(), totalMs);
  if (!a.mosaic.empty()) {
    if (sv::Status s = sv::writeImage(sv::mosaic(images), a.mosaic); !s) return fail(s.error());
    fmt::print("{}: the {} channels side by side\n", a.mosaic, images.size());
  }
  return 0;
}

// --display: every projector's pre-distorted, blended frame as OUT-<projector>.png with a line
// each, the viewer's panorama and the rig's MPCDI file if asked for.
int renderDisplay(const RenderArgs& a, const sv::scene::Scene& scene, const sv::RenderOptions& o) {
  const auto correction = sv::render::parseCorrection(a.correction);
  if (!correction) return fail(correction.error());
  sv::render::DisplaySetup display;
  if (a.display == "cylinder3") {
    display = sv::render::cylinderDisplay(o.width, o.height);
  } else {
    auto read = sv::render::mpcdiDisplay(a.display);
    if (!read) return fail(read.error());
    display = std::move(read).value();
  }
  if (!a.writeMpcdi.empty()) {
    auto m = sv::render::mpcdiOf(display);
    if (!m) return fail(m.error());
    if (sv::Status s = sv::display::writeMpcdi(a.writeMpcdi, m.value()); !s) return fail(s.error());
    fmt::print("{}: the display as MPCDI (3d profile, {} regions)\n", a.writeMpcdi,
               display.projectors.size());
  }
  sv::render::CorrectionRenderer renderer(o);
  sv::render::DisplayFrame frame;
  if (sv::Status s = sv::render::renderDisplay(renderer, scene, o, display, correction.value(), frame);
      !s) {
    sv::Error e = s.error();
    if (e.file.empty()) e.file = a.scene.empty() ? "<demo scene>" : a.scene;
    return fail(e);
  }
  double totalMs = 0;
  for (size_t i = 0; i < frame.images.size(); ++i) {
    const std::string path = withSuffix(a.output, display.projectors[i].name);
    if (sv::Status s = sv::writeImage(frame.images[i], path); !s) return fail(s.error());
    const sv::render::CorrectionStats& c = frame.correction[i];
    const std::string how =
        correction.value() == sv::render::Correction::subFrusta
            ? fmt::format("{} sub-frusta, residual <= {:.3f} px, plan {:.1f} ms", c.cells,
                          c.maxResidualPixels, c.planMs)
            : fmt::format("flat {}x{} resampled {} in {:.1f} ms", c.flatWidth, c.flatHeight,
                          a.correction, c.resampleMs);
    fmt::print("{}: {}x{} | {} | {}\n", path, frame.images[i].width, frame.images[i].height, how,
               frame.stats[i].summary());
    totalMs += frame.stats[i].totalMs;
  }
  fmt::print("frame: {} projectors, {:.2f} ms\n", frame.images.size(), totalMs);
  if (!a.viewer.empty()) {
    auto image = sv::render::viewerImage(display, frame, sv::display::PanoramaView{},
                                         renderer.gamma());
    if (!image) return fail(image.error());
    if (sv::Status s = sv::writeImage(image.value(), a.viewer); !s) return fail(s.error());
    fmt::print("{}: the viewer's view of the screen, azimuth -100 … 100°, elevation -25 … 25°\n",
               a.viewer);
  }
  return 0;
}

int runRender(const RenderArgs& a) {
  sv::RenderOptions o = a.options;
  o.cullBackFaces = !a.noCull;
  o.cullInstances = !a.noInstanceCull;
  auto filter = parseFilter(a.filter);
  if (!filter) return fail(filter.error());
  o.filter = filter.value();
  auto textureFilter = sv::scene::parseTextureFilter(a.textureFilter);
  if (!textureFilter) return fail(textureFilter.error());
  o.textureFilter = textureFilter.value();
  auto hsr = sv::parseHsr(a.hsr);
  if (!hsr) return fail(hsr.error());
  o.hsr = hsr.value();
  auto pipeline = sv::parsePipeline(a.pipeline);
  if (!pipeline) return fail(pipeline.error());
  o.pipeline = pipeline.value();
  if (a.freeform != "raycast" && a.freeform != "march")
    return fail(
        {"", "", fmt::format("unknown free-form method '{}' (raycast or march)", a.freeform)});
  o.freeFormMethod = a.freeform == "march" ? sv::RenderOptions::FreeFormMethod::march
                                           : sv::RenderOptions::FreeFormMethod::raycast;
  if (a.terrainFilter == "bilinear")
    o.terrainFilter = sv::RenderOptions::TerrainFilter::bilinear;
  else if (a.terrainFilter == "bicubic")
    o.terrainFilter = sv::RenderOptions::TerrainFilter::bicubic;
  else if (a.terrainFilter != "scene")
    return fail({"", "",
                 fmt::format("unknown terrain filter '{}' (scene, bilinear or bicubic)",
                             a.terrainFilter)});
  if (!a.debugView.empty()) {
    using DebugView = sv::RenderOptions::DebugView;
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
  if (sv::Status s = sv::validate(o); !s) return fail(s.error());

  auto loaded = loadSceneOrDemo(a.scene);
  if (!loaded) return fail(loaded.error());
  sv::scene::Scene scene = std::move(loaded).value();
  if (a.time) {
    if (!std::isfinite(*a.time)) return fail({"", "", "--time: not a finite number of seconds"});
    scene.time = *a.time;
  }
  if (sv::Status s = addArcChannels(scene, o, a.channels, a.arc); !s) {
    sv::Error e = s.error();
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
  sv::Renderer renderer(o);
  if (!scene.channels.empty()) return renderChannels(a, scene, renderer);
  if (!a.mosaic.empty())
    return fail({"", "", "--mosaic: the scene has no channels (add --channels N)"});
  sv::Image image;
  sv::FrameStats stats;
  if (sv::Status s = renderer.render(scene, image, &stats); !s) {
    sv::Error e = s.error();
    if (e.file.empty()) e.file = a.scene.empty() ? "<demo scene>" : a.scene;
    return fail(e);
  }
  if (sv::Status s = sv::writeImage(image, a.output); !s) return fail(s.error());
  fmt::print("{}: {}x{} | {}\n", a.output, o.width, o.height, stats.summary());
  return 0;
}

// The parameters of BENCH.md's generators, shared by `bench` and `gen`.
struct GeneratorArgs {
  sv::generators::TrisParams tris;
  int layers = 4;
  std::string order = "random";
  int objects = 100;
  int size = 4096;  // terrain: heights a side
  std::string terrainFilter = "bilinear";
  std::string stars = "auto";  // lights: the star catalogue, "auto" or "none"
  int lights = 100000;         // lights: light points per channel, stars included
  sv::generators::CityParams city;
  sv::generators::VolumeParams volume;
};

// lights --stars auto: xplanet's catalogue where Debian installs it, or where scripts/lib.sh
// (sv_data) unpacks it in a checkout (the current directory); none if neither is there.
std::string starCatalog(const std::string& option) {
  if (option == "none") return "";
  if (option != "auto") return option;
  for (const char* path :
       {"/usr/share/xplanet/stars/BSC", "build-data/root/usr/share/xplanet/stars/BSC"})
    if (std::FILE* f = std::fopen(path, "rb")) {
      std::fclose(f);
      return path;
    }
  return "";
}

void addGeneratorOptions(CLI::App* app, GeneratorArgs& g) {
  app->add_option("--count", g.tris.count, "tris: number of triangles")->capture_default_str();
  app->add_option("--lights", g.lights, "lights: light points, stars included")
      ->capture_default_str();
  app->add_option("--buildings", g.city.buildings, "city: buildings, one per 40 m block")
      ->capture_default_str();
  app->add_option("--trees", g.city.trees, "city: trees")->capture_default_str();
  app->add_option("--voxels", g.volume.size, "volume: samples a side")->capture_default_str();
  app->add_flag("--opaque", g.volume.opaque, "volume: iso-surface-like (opaque above the threshold)");
  app->add_flag("--no-shell", [&g](int64_t) { g.volume.shell = false; },
                "volume: cast through the whole box, without the free-form shell");
  app->add_flag("--precomputed-normals", g.volume.precomputedNormals,
                "volume: gradient directions precomputed per sample (SPEC §11's second way)");
  app->add_option("--stars", g.stars,
                  "lights: the star catalogue (xplanet's BSC), auto (found where Debian or "
                  "scripts/lib.sh puts it) or none")
      ->capture_default_str();
  app->add_option("--area", g.tris.area, "tris: mean projected area, pixels")
      ->capture_default_str();
  app->add_option("--depth", g.tris.depth, "tris: depth complexity (0 = whole screen)")
      ->capture_default_str();
  app->add_option("--layers", g.layers, "layers: depth complexity D")->capture_default_str();
  app->add_option("--objects", g.objects, "freeform: number of perturbed quadrics")
      ->capture_default_str();
  app->add_option("--order", g.order, "tris, layers: random, f2b or b2f")->capture_default_str();
  app->add_option("--size", g.size, "terrain: heights a side (the map is 40.96 km square)")
      ->capture_default_str();
  app->add_option("--terrain-filter", g.terrainFilter,
                  "terrain: interpolation below the finest level, bilinear or bicubic")
      ->capture_default_str();
  app->add_option("--seed", g.tris.seed, "generator seed")->capture_default_str();
}

struct BenchArgs {
  std::string scene;
  std::string suite;
  GeneratorArgs generator;
  std::string shade = "gouraud";
  bool fog = false;
  std::string textureFilter = "trilinear";
  std::string hsr = "zbuffer";
  std::string renderer;  // synthvis, gl or both; default synthvis for a scene, both for a suite
  std::string json;
  std::string html;
  std::string image;
  int frames = 10;
  int warmup = 2;
  int repeat = 1;  // measurements of each scene (each with its warm-up and timed frames)
  int aa = 1;
  std::string terrainLod = "on";
  int glAa = -1;  // -1: as --aa, capped at llvmpipe's 4
  std::string filter = "box";
  bool glReadback = false;
  int channels = 0;  // BENCH.md --channels N (SPEC §9)
  float arc = 150;   // … abutting in this arc, degrees
  std::string pipeline = "tiles";  // segments: as --renderer segments
  sv::RenderOptions options{.width = 1920, .height = 1080, .threads = 2};
};

// The case for generator `kind` with the given parameters; an error names a generator that needs
// a later feature, or an unknown one.
sv::Result<sv::reference::BenchCase> generatorCase(const std::string& kind,
                                                   const GeneratorArgs& g) {
  auto generator = sv::generators::parseGenerator(kind);
  if (!generator) return generator.error();
  auto order = sv::generators::parseSubmitOrder(g.order);
  if (!order) return order.error();
  sv::reference::BenchCase c;
  c.name = kind;
  c.generator = generator.value();
  c.tris = g.tris;
  c.tris.order = order.value();
  c.layers.layers = g.layers;
  c.layers.order = order.value();
  c.layers.seed = g.tris.seed;
  c.grazing.seed = g.tris.seed;
  c.freeform.count = g.objects;
  c.freeform.seed = g.tris.seed;
  c.terrain.size = g.size;
  c.terrain.seed = g.tris.seed;
  auto interp = sv::terrain::parseInterpolation(g.terrainFilter);
  if (!interp) return interp.error();
  c.terrain.bicubic = interp.value() == sv::terrain::Interpolation::bicubic;
  c.lights.count = g.lights;
  c.lights.seed = g.tris.seed;
  c.lights.starCatalog = starCatalog(g.stars);
  c.city = g.city;
  c.city.seed = g.tris.seed;
  c.volume = g.volume;
  c.volume.seed = g.tris.seed;
  return c;
}

// bench --channels N --arc DEG: 0 (the classic view) … 16 channels, each under 180°.
sv::Status checkBenchChannels(int channels, float arc) {
  if (channels < 0 || channels > int(sv::scene::kMaxChannels))
    return sv::Error{"", "",
                     fmt::format("--channels {}: must be 0…{}", channels, sv::scene::kMaxChannels)};
  if (!(arc > 0 && arc < 180.0f * float(std::max(channels, 1))))
    return sv::Error{"", "",
                     fmt::format("--arc {}: must be more than 0 and less than 180 a channel", arc)};
  return {};
}

int runBench(BenchArgs a) {
  namespace ref = sv::reference;
  a.options.samples = a.aa == 0 ? 1 : a.aa;
  if (a.terrainLod != "on" && a.terrainLod != "off")
    return fail({"", "", fmt::format("--terrain-lod is on or off, not '{}'", a.terrainLod)});
  a.options.terrainLod = a.terrainLod == "on";
  if (auto f = parseFilter(a.filter); !f)
    return fail(f.error());
  else
    a.options.filter = f.value();
  if (a.shade != "gouraud" && a.shade != "textured")
    return fail({"", "", fmt::format("unknown shading '{}' (gouraud or textured)", a.shade)});
  if (auto f = sv::scene::parseTextureFilter(a.textureFilter); !f)
    return fail(f.error());
  else
    a.options.textureFilter = f.value();
  if (auto h = sv::parseHsr(a.hsr); !h)
    return fail(h.error());
  else
    a.options.hsr = h.value();
  auto pipeline = sv::parsePipeline(a.pipeline);
  if (!pipeline) return fail(pipeline.error());
  if (pipeline.value() == sv::RenderOptions::Pipeline::segments) {
    if (!a.renderer.empty() && a.renderer != "segments")
      return fail({"", "", "--pipeline segments is measured against the tiles: drop --renderer"});
    a.renderer = "segments";
  }
  // The segment pipeline's options are checked as the segment renderer's.
  if (a.renderer == "segments") a.options.pipeline = sv::RenderOptions::Pipeline::segments;
  if (sv::Status s = sv::validate(a.options); !s) return fail(s.error());
  if (sv::Status s = checkBenchChannels(a.channels, a.arc); !s) return fail(s.error());
  if (a.scene.empty() == a.suite.empty())
    return fail({"", "", "give either a scene (a generator name or a file) or --suite quick|full"});
  if (a.renderer.empty()) a.renderer = a.suite.empty() ? "synthvis" : "both";
  if (a.renderer != "synthvis" && a.renderer != "gl" && a.renderer != "both" &&
      a.renderer != "sphere-trace" && a.renderer != "tessellated" &&
      a.renderer != "full-detail" && a.renderer != "vtk" && a.renderer != "display" &&
      a.renderer != "segments")
    return fail({"", "",
                 fmt::format("unknown renderer '{}' (synthvis, gl, vtk, both, sphere-trace, "
                             "tessellated, full-detail, display or segments)",
                             a.renderer)});
  if (auto order = sv::generators::parseSubmitOrder(a.generator.order); !order)
    return fail(order.error());
  if (a.repeat < 1 || a.repeat > 100)
    return fail({"", "", fmt::format("--repeat {}: must be 1…100", a.repeat)});
  if (a.glAa == -1) a.glAa = a.aa >= 2 ? std::min(a.aa, 4) : 0;
  if (a.glAa != 0 && a.glAa != 2 && a.glAa != 4 && a.glAa != 8 && a.glAa != 16)
    return fail({"", "",
                 fmt::format("--gl-aa {}: the reference's samples per pixel must be 0, 2, "
                             "4, 8 or 16",
                             a.glAa)});

  std::vector<ref::BenchCase> cases;
  if (!a.suite.empty()) {
    auto c = ref::suiteCases(a.suite);
    if (!c) return fail(c.error());
    cases = std::move(c).value();
  } else {
    ref::BenchCase c;
    if (sv::generators::parseGenerator(a.scene).ok()) {
      auto g = generatorCase(a.scene, a.generator);
      if (!g) return fail(g.error());
      c = g.value();
    } else {
      c.name = a.scene;
      c.file = a.scene;
    }
    cases.push_back(c);
  }

  ref::BenchSettings settings;
  settings.options = a.options;
  settings.frames = a.frames;
  settings.warmup = a.warmup;
  settings.referenceMsaa = a.glAa;
  settings.referenceReadback = a.glReadback;
  settings.textured = a.shade == "textured";
  settings.fog = a.fog;
  settings.channels = a.channels;
  settings.arcDegrees = a.arc;
  settings.synthvis = a.renderer != "gl" && a.renderer != "vtk";
  settings.vtk = a.renderer == "vtk" || a.renderer == "both";
  settings.sphereTrace = a.renderer == "sphere-trace";
  settings.tessellated = a.renderer == "tessellated";
  settings.fullDetail = a.renderer == "full-detail";
  settings.display = a.renderer == "display";
  settings.pipelines = a.renderer == "segments";
  settings.reference = a.renderer == "gl" || a.renderer == "both";
  ref::BenchRunner runner(settings);
  if (settings.reference) {
    if (sv::Status s = runner.startReference(); !s) {
      // A suite still runs on synthvis alone and says so; asking for gl alone cannot.
      if (a.renderer == "gl") return fail(s.error());
      fmt::print("reference: not available: {}\n", s.error().str());
      settings.reference = false;
    } else {
      fmt::print("reference: {} (LP_NUM_THREADS={})\n", runner.referenceDescription(),
                 a.options.threads);
    }
  }

  if (settings.synthvis) fmt::print("synthvis: SIMD target {}\n", ref::simdTarget());
  std::vector<ref::CaseResult> results;
  nlohmann::json rows = nlohmann::json::array();
  for (size_t i = 0; i < cases.size(); ++i) {
    if (cases.size() > 1) fmt::print("[{}/{}] {} …\n", i + 1, cases.size(), cases[i].name);
    std::vector<ref::CaseResult> repeats;
    for (int k = 0; k < a.repeat; ++k) {
      if (a.repeat > 1) fmt::print("repeat {}/{}\n", k + 1, a.repeat);
      std::fflush(stdout);
      auto r = runner.run(cases[i]);
      if (!r) {
        sv::Error e = r.error();
        if (e.file.empty() && !cases[i].file.empty()) e.file = cases[i].file;
        return fail(e);
      }
      const ref::CaseResult& cr = r.value();
      if (k == 0 && !cr.params.contains("file"))
        fmt::print("{}: {} triangles, mean area {:.1f} px, depth complexity {:.2f}\n", cr.name,
                   cr.triangles, cr.meanArea, cr.depthComplexity);
      if (k == 0 && cr.params.value("volumes_alone", false))
        fmt::print("{}: the scene's volumes alone, in both renderers (VTK draws nothing else)\n",
                   cr.name);
      fmt::print("{}\n", ref::summaryLine(cr));
      if (settings.synthvis && cr.runs[0].channelStats.empty())
        fmt::print("  synthvis last frame: {}\n", cr.runs[0].stats.summary());
      for (size_t c = 0; c < cr.runs[0].channelStats.size(); ++c)
        fmt::print("  synthvis last frame, channel {}: {}\n", c,
                   cr.runs[0].channelStats[c].summary());
      if (settings.pipelines && cr.runs.size() > 1)
        fmt::print("  segments last frame: {}\n"
                   "  segments: {:.1f} M/s, lines repeated {} ({:.1f} %)\n",
                   cr.runs[1].stats.summary(),
                   cr.params.value("segments_per_second", 0.0) / 1e6,
                   cr.params.value("repeated_lines", uint64_t(0)),
                   100 * cr.params.value("repeated_share", 0.0));
      for (auto& row : ref::jsonRows(cr, settings)) {
        if (a.repeat > 1) row["repeat"] = k + 1;
        rows.push_back(row);
      }
      repeats.push_back(std::move(r).value());
    }
    // The pages and images show the repetition the median line names.
    size_t median = 0;
    if (a.repeat > 1) fmt::print("{}\n", ref::repeatSummaryLine(repeats, median));
    results.push_back(std::move(repeats[median]));
  }

  if (!a.image.empty()) {
    // The first renderer's frame to FILE; a second renderer's beside it, FILE's stem + "-" + its
    // name (out.png → out-gl.png), for `synthvis compare`.
    const std::vector<ref::RendererRun>& runs = results.back().runs;
    if (sv::Status s = sv::writeImage(runs[0].image, a.image); !s) return fail(s.error());
    if (runs.size() > 1)
      if (sv::Status s = sv::writeImage(runs[1].image, withSuffix(a.image, runs[1].renderer)); !s)
        return fail(s.error());
  }
  if (!a.json.empty()) {
    // One scene on one renderer: an object (BENCH.md); otherwise a list of rows.
    const std::string text = (rows.size() == 1 ? rows[0] : rows).dump(2) + "\n";
    if (sv::Status s = sv::core::writeFile(a.json, {text}); !s) return fail(s.error());
  }
  if (!a.html.empty()) {
    if (sv::Status s = ref::writeHtml(a.html, results, settings, runner.referenceDescription()); !s)
      return fail(s.error());
    fmt::print("html: {}/index.html\n", a.html);
  }
  return 0;
}

struct GenArgs {
  std::string kind;
  std::string output;
  GeneratorArgs generator;
  int width = 1920, height = 1080;
  std::string shade = "gouraud";
};

// `synthvis gen KIND -o scene.glb`: a BENCH.md scene as glTF, for other renderers.
int runGen(const GenArgs& a) {
  if (a.width < 1 || a.width > sv::kMaxRasterSize || a.height < 1 || a.height > sv::kMaxRasterSize)
    return fail({"", "", "width and height must be 1…8192"});
  if (a.shade != "gouraud" && a.shade != "textured")
    return fail({"", "", fmt::format("unknown shading '{}' (gouraud or textured)", a.shade)});
  auto c = generatorCase(a.kind, a.generator);
  if (!c) return fail(c.error());
  c.value().tris.textured = c.value().layers.textured = a.shade == "textured";
  sv::RenderOptions o;
  o.width = a.width;
  o.height = a.height;
  auto made = sv::reference::makeScene(c.value(), o);
  if (!made) return fail(made.error());
  if (sv::Status s = sv::formats::saveGltf(made.value().scene, a.output); !s)
    return fail(s.error());
  if (made.value().meanArea > 0)
    fmt::print("{}: {} {} triangles, mean area {:.1f} px at {}x{}, depth complexity {:.2f}\n",
               a.output, a.kind, made.value().scene.triangleCount(), made.value().meanArea, a.width,
               a.height, made.value().depthComplexity);
  else
    fmt::print("{}: {} {} triangles, {} textures\n", a.output, a.kind,
               made.value().scene.triangleCount(), made.value().scene.textures.size());
  return 0;
}

struct PrepArgs {
  std::string input;
  std::string output;
  GeneratorArgs generator;
  bool noOptimize = false, noLods = false;
  sv::prep::PrepOptions options;
};

// `synthvis prep INPUT -o DB.svdb`: the database preparation system (docs/prep.md). INPUT is any
// scene file, or the name of a BENCH.md generator (city).
int runPrep(const PrepArgs& a) {
  using Clock = std::chrono::steady_clock;
  auto seconds = [](Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
  };
  auto t0 = Clock::now();
  sv::Result<sv::scene::Scene> loaded = sv::Error{"", "", ""};
  if (sv::generators::parseGenerator(a.input).ok()) {
    auto c = generatorCase(a.input, a.generator);
    if (!c) return fail(c.error());
    auto made = sv::reference::makeScene(c.value(), sv::RenderOptions{});
    if (!made) return fail(made.error());
    loaded = std::move(made.value().scene);
  } else {
    loaded = loadSceneOrDemo(a.input);
  }
  if (!loaded) return fail(loaded.error());
  sv::scene::Scene scene = std::move(loaded).value();
  fmt::print("prep: read {} in {:.2f} s: {} meshes, {} instances, {} triangles over them\n",
             a.input, seconds(t0), scene.meshes.size(), scene.instances.size(),
             scene.triangleCount());
  sv::prep::PrepOptions o = a.options;
  o.optimize = !a.noOptimize;
  o.generateLods = !a.noLods;
  t0 = Clock::now();
  auto report = sv::prep::prepare(scene, o, [](size_t done, size_t total) {
    fmt::print(stderr, "\rprep: meshes {}/{}", done, total);
    if (done == total) fmt::print(stderr, "\n");
  });
  if (!report) return fail(report.error());
  fmt::print("prep: prepared in {:.2f} s: {}\n", seconds(t0), report->summary());
  t0 = Clock::now();
  if (sv::Status s = sv::formats::saveDatabase(scene, a.output); !s) return fail(s.error());
  const double written = seconds(t0);
  // The load time a user of the database will see: mapped, checked, copied out.
  t0 = Clock::now();
  auto back = sv::formats::loadDatabase(a.output);
  if (!back) return fail(back.error());
  const double load = seconds(t0);
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(a.output, ec);
  fmt::print("prep: wrote {} ({:.1f} MB) in {:.2f} s; it loads in {:.1f} ms\n", a.output,
             double(bytes) / 1e6, written, load * 1e3);
  return 0;
}

struct TruthArgs {
  std::string scene;
  std::string output = "truth.png";
  std::string edges;
  int samples = 256;
  bool noCull = false;
  sv::RenderOptions options;
};

// `synthvis truth [SCENE] -o truth.png --samples 256`: the ground-truth image (src/reference).
int runTruth(const TruthArgs& a) {
  const int side = int(std::lround(std::sqrt(double(a.samples))));
  if (side < 1 || side > 32 || side * side != a.samples)
    return fail({"", "", fmt::format("--samples {}: must be a square from 1 to 1024", a.samples)});
  sv::reference::GroundTruthOptions g;
  g.options = a.options;
  g.options.cullBackFaces = !a.noCull;
  g.samplesPerSide = side;
  auto loaded = loadSceneOrDemo(a.scene);
  if (!loaded) return fail(loaded.error());
  const sv::scene::Scene scene = std::move(loaded).value();
  fmt::print("{}: {}x{}, {} samples per pixel…\n", a.output, g.options.width, g.options.height,
             a.samples);
  std::fflush(stdout);
  sv::Image edges;
  auto image = sv::reference::renderGroundTruth(scene, g, &edges);
  if (!image) return fail(image.error());
  if (sv::Status s = sv::writeImage(image.value(), a.output); !s) return fail(s.error());
  if (!a.edges.empty())
    if (sv::Status s = sv::writeImage(edges, a.edges); !s) return fail(s.error());
  return 0;
}

// `synthvis compare IMAGE REFERENCE`: differences in linear light, all pixels and edge pixels.
int runCompare(const std::string& imagePath, const std::string& referencePath,
               const std::string& edgesPath) {
  auto a = sv::readPng(imagePath);
  if (!a) return fail(a.error());
  auto b = sv::readPng(referencePath);
  if (!b) return fail(b.error());
  sv::Result<sv::Image> mask = sv::Image{};
  if (!edgesPath.empty()) {
    mask = sv::readPng(edgesPath);
    if (!mask) return fail(mask.error());
  }
  auto d = sv::reference::compareImages(a.value(), b.value(),
                                        edgesPath.empty() ? nullptr : &mask.value());
  if (!d) return fail({imagePath, "", d.error().message});
  const auto& r = d.value();
  fmt::print(
      "all pixels ({}): RMSE {:.6f}, PSNR {:.2f} dB | edge pixels ({}): RMSE {:.6f}, "
      "PSNR {:.2f} dB (linear light)\n",
      r.pixels, r.rmse, r.psnrDb, r.edgePixels, r.edgeRmse, r.edgePsnrDb);
  return 0;
}

// `synthvis terrain SCENE --height X,Y,Z | --los X,Y,Z,X,Y,Z`: the host's queries (synthvis/terrain.h).
// synthvis ig: the real-time loop a host drives (docs/ig.md).
int runIg(const std::string& configPath, sv::ig::IgRunOptions options) {
  // A y4m reader that goes away is the presenter's closed(), not the end of the process.
  std::signal(SIGPIPE, SIG_IGN);
  // Under mpirun, one rank of the IG (docs/cluster.md); an error on any rank ends the whole job,
  // named, rather than leaving the others waiting for it.
  sv::Result<std::unique_ptr<sv::cluster::Cluster>> cluster = sv::cluster::Cluster::join();
  if (!cluster) return fail(cluster.error());
  sv::cluster::Cluster& job = *cluster.value();
  options.cluster = &job;
  const auto failJob = [&](sv::Error e) {
    if (e.file.empty()) e.file = configPath;
    if (job.size() > 1) job.abort(fmt::format("{}: {}", job.name(job.rank()), e.str()));
    return fail(e);
  };
  sv::Result<sv::ig::IgConfig> config = sv::ig::loadIgConfig(configPath);
  if (!config) return failJob(config.error());
  sv::Result<std::unique_ptr<sv::ig::IgLoop>> loop = sv::ig::IgLoop::create(config.value(), options);
  if (!loop) return failJob(loop.error());
  if (options.replay.empty() && job.rank() == 0)
    fmt::print(stderr, "synthvis ig: {} at {:.0f} Hz, listening on UDP {}{}\n", configPath,
               config->rate, loop.value()->port(),
               job.size() > 1 ? fmt::format(", {} ranks", job.size()) : std::string());
  sv::Result<sv::ig::IgRunReport> report = loop.value()->run();
  if (!report) return failJob(report.error());
  fmt::print(stderr, "{}{}\n", job.size() > 1 ? job.name(job.rank()) + ": " : std::string(),
             report->summary());
  return 0;
}

// synthvis host: the scripted host (docs/ig.md).
int runHost(const std::string& scriptPath, int igPort, int port, long long frames) {
  sv::Result<sv::ig::HostScript> script = sv::ig::loadHostScript(scriptPath);
  if (!script) return fail(script.error());
  if (igPort > 0) script->igPort = uint16_t(igPort);
  if (port >= 0) script->port = uint16_t(port);
  if (frames > 0) script->frames = uint64_t(frames);
  sv::Result<sv::ig::HostLog> log = sv::ig::runHost(script.value());
  if (!log) return fail(log.error());
  fmt::print("host: {} frames sent, {} Start of Frame received (last IG frame {})\n",
             log->framesSent, log->startOfFrames, log->lastIgFrame);
  for (const sv::cigi::HatHotResponse& h : log->heights)
    fmt::print("{} {}: {}\n", h.hot ? "HOT" : "HAT", h.id,
               h.valid ? fmt::format("{:.3f} m", h.height) : std::string("no ground"));
  for (const sv::cigi::LosResponse& l : log->linesOfSight)
    fmt::print("LOS {}: {}\n", l.id,
               l.valid ? fmt::format("blocked at {:.3f} m", l.range) : std::string("clear"));
  return 0;
}

int runTerrainQuery(const std::string& scenePath, const std::vector<double>& at,
                    const std::vector<double>& los, const std::string& filterName) {
  using Filter = sv::RenderOptions::TerrainFilter;
  Filter filter = Filter::scene;
  if (filterName == "bilinear")
    filter = Filter::bilinear;
  else if (filterName == "bicubic")
    filter = Filter::bicubic;
  else if (filterName != "scene")
    return fail({"", "", fmt::format("unknown terrain filter '{}' (scene, bilinear or bicubic)",
                                     filterName)});
  if (at.empty() == los.empty())
    return fail({"", "", "give one query: --height X,Y,Z or --los X,Y,Z,X,Y,Z"});
  auto loaded = sv::formats::loadScene(scenePath);
  if (!loaded) return fail(loaded.error());
  const sv::scene::Scene& scene = loaded.value();
  if (scene.terrains.empty()) return fail({scenePath, "", "the scene has no terrain"});
  if (!at.empty()) {
    const auto h = sv::terrainHeight(scene, at[0], at[1], at[2], filter);
    if (!h) {
      fmt::print("no terrain under ({}, {}, {})\n", at[0], at[1], at[2]);
      return 1;
    }
    fmt::print("terrain {}: ground at {:.4f} m, the point {:.4f} m above it\n", h->terrain,
               h->elevation, h->above);
    return 0;
  }
  const auto hit = sv::lineOfSight(scene, los.data(), los.data() + 3, filter);
  if (!hit) {
    fmt::print("clear: the line of sight does not meet the ground\n");
    return 0;
  }
  fmt::print("blocked by terrain {} at ({:.4f}, {:.4f}, {:.4f}), {:.6f} of the way\n", hit->terrain,
             hit->x, hit->y, hit->z, hit->fraction);
  return 0;
}

// The `render` subcommand's options, into `r`.
// The segment pipeline's video channel (RenderOptions::SegmentChannel), for render and bench.
void addSegmentChannelOptions(CLI::App* app, sv::RenderOptions& o) {
  app->add_flag("--donor", o.segmentChannel.donor,
                "segment pipeline: the recipient-donor anti-aliasing filter (seed 002's 1x1 box)");
  app->add_flag("--interlaced", o.segmentChannel.interlaced,
                "segment pipeline: two fields a frame, even lines then odd");
  app->add_option("--segment-rate", o.segmentChannel.wordsPerLine,
                  "segment pipeline: the geometry stage's rate in segment words per line period "
                  "(overload protection repeats lines it cannot deliver in time; 0 = unlimited)")
      ->capture_default_str();
  app->add_option("--critical-lines", o.segmentChannel.criticalLines,
                  "segment pipeline: lines buffered ahead of the display below which a line is "
                  "repeated")
      ->capture_default_str();
  app->add_option("--fifo-words", o.segmentChannel.fifoWords,
                  "segment pipeline: the FIFO's capacity in segment words")
      ->capture_default_str();
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
  render->add_flag("--no-lod", [&r](int64_t) { r.options.lod = false; },
                   "draw every instance at full detail (level 0) at every range");
  render->add_flag("--no-merge", [&r](int64_t) { r.options.mergeCells = false; },
                   "draw every instance on its own, also where its merged cell would do");
  render->add_option("--lod-scale", r.options.lodScale,
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
                   "anti-aliasing: samples per pixel, 1 (none), 4, 8, 16 or 64")
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

int main(int argc, char** argv) {
  CLI::App app{"synthvis — a real-time software image generator (recursive 2x2 subdivision)"};
  app.require_subcommand(1);

  RenderArgs r;
  CLI::App* render = app.add_subcommand("render", "render a scene to an image");
  addRenderOptions(render, r);

  BenchArgs b;
  CLI::App* bench =
      app.add_subcommand("bench", "time whole frames of a benchmark scene (BENCH.md)");
  bench->add_option("scene", b.scene,
                    "generator (tris, layers, grazing, freeform, freeform-one) or scene file");
  bench->add_option("--suite", b.suite, "a named suite of scenes: quick or full");
  addGeneratorOptions(bench, b.generator);
  bench
      ->add_option("--shade", b.shade,
                   "generated scenes: gouraud, or textured (BENCH.md's 1024x1024 texture)")
      ->capture_default_str();
  bench->add_flag("--fog", b.fog, "generated scenes: BENCH.md's fog (haze, beta 0.1 per unit)");
  bench->add_option("--pipeline", b.pipeline,
                    "tiles, or segments: the same as --renderer segments")
      ->capture_default_str();
  addSegmentChannelOptions(bench, b.options);
  bench->add_option("--hsr", b.hsr, "hidden surfaces: zbuffer, priority or hybrid")
      ->capture_default_str();
  bench
      ->add_option("--texture-filter", b.textureFilter,
                   "nearest, tri3, bilinear, trilinear3, trilinear or aniso")
      ->capture_default_str();
  bench->add_option("--width", b.options.width, "image width")->capture_default_str();
  bench->add_option("--height", b.options.height, "image height")->capture_default_str();
  bench->add_option("--threads", b.options.threads, "worker threads")->capture_default_str();
  bench->add_flag("--no-instance-cull", [&b](int64_t) { b.options.cullInstances = false; },
                  "transform every instance, also those wholly outside the view");
  bench->add_flag("--no-lod", [&b](int64_t) { b.options.lod = false; },
                  "draw every instance at full detail (level 0) at every range");
  bench->add_flag("--no-merge", [&b](int64_t) { b.options.mergeCells = false; },
                  "draw every instance on its own, also where its merged cell would do");
  bench->add_option("--lod-scale", b.options.lodScale, "multiplies every level-of-detail range")
      ->capture_default_str();
  bench->add_option("--frames", b.frames, "timed frames")->capture_default_str();
  bench->add_option("--warmup", b.warmup, "untimed frames first")->capture_default_str();
  bench
      ->add_option("--repeat", b.repeat,
                   "measure each scene N times (warm-up and timed frames each) and print the "
                   "medians over them, with the ratio's range")
      ->capture_default_str();
  bench->add_option("--aa", b.aa, "synthvis: samples per pixel (1, 4, 8, 16, 64)")
      ->capture_default_str();
  bench->add_option(
      "--gl-aa", b.glAa,
      "the gl reference's multisamples (0, 2, 4, 8, 16); default: as --aa, at most 4");
  bench->add_option("--filter", b.filter, "synthvis resolve filter: box or tent3")
      ->capture_default_str();
  bench
      ->add_option("--supersample", b.options.supersample,
                   "synthvis: k×k samples per pixel, averaged (1, 2, 4, 8, 16)")
      ->capture_default_str();
  bench->add_flag("--gl-readback", b.glReadback,
                  "count the gl reference's read-back of the image in its frame time");
  bench->add_option("--renderer", b.renderer,
                    "synthvis, gl (Mesa llvmpipe), vtk (VTK's CPU volume ray caster, for "
                    "scenes of volumes alone) or both (gl, or vtk for volumes), alternating "
                    "frames; sphere-trace: "
                    "synthvis against its free forms marched in fixed steps (--march-steps); "
                    "tessellated: against its free forms as triangles (the gl reference always "
                    "draws those); full-detail: against every instance transformed at full "
                    "detail (no instance culling, no levels of detail); display: the unwarped "
                    "view against the centre projector of --display cylinder3 pre-distorted "
                    "through sub-frusta (subfrusta) and by a flat view resampled (resampled); "
                    "segments: the tile pipeline under priority masking against seed 002's "
                    "segment pipeline (one sample, vertex colours); "
                    "default: synthvis for a scene, both for a suite");
  bench
      ->add_option("--march-steps", b.options.marchSteps,
                   "sphere-trace: depth steps per ray of the fixed-step marcher")
      ->capture_default_str();
  bench->add_option("--json", b.json, "write the results as JSON to this file");
  bench->add_option("--html", b.html, "write an HTML page with plots and images to this directory");
  bench->add_option("--terrain-lod", b.terrainLod,
                    "terrain: on (levels of detail where a pixel spans more than a grid step) or "
                    "off (the table's own surface everywhere)")
      ->capture_default_str();
  bench
      ->add_option("--channels", b.channels,
                   "display channels: N abutting views (each --width x --height) in one frame; the "
                   "time is the whole frame's (synthvis only)")
      ->capture_default_str();
  bench->add_option("--arc", b.arc, "--channels: the arc they span, degrees")
      ->capture_default_str();
  bench->add_option("--image", b.image,
                    "write the last frame of the last scene to this image file");

  GenArgs g;
  CLI::App* gen = app.add_subcommand("gen", "write a BENCH.md scene as glTF (.glb or .gltf)");
  gen->add_option("kind", g.kind, "generator: tris, layers or grazing")->required();
  gen->add_option("-o,--output", g.output, "output file (.glb or .gltf)")->required();
  addGeneratorOptions(gen, g.generator);
  gen->add_option("--width", g.width, "the raster the areas refer to")->capture_default_str();
  gen->add_option("--height", g.height, "the raster the areas refer to")->capture_default_str();
  gen->add_option("--shade", g.shade,
                  "tris, layers: gouraud, or textured (BENCH.md's 1024x1024 texture, as a PNG)")
      ->capture_default_str();

  TruthArgs tr;
  CLI::App* truth = app.add_subcommand(
      "truth", "render the ground-truth image: brute force, n×n samples per pixel, box filter");
  truth->add_option("scene", tr.scene, "scene file; default: built-in demo");
  truth->add_option("-o,--output", tr.output, "output image (.png or .ppm)")->capture_default_str();
  truth->add_option("--samples", tr.samples, "samples per pixel, a square (1…1024)")
      ->capture_default_str();
  truth->add_option("--width", tr.options.width, "image width in pixels")->capture_default_str();
  truth->add_option("--height", tr.options.height, "image height in pixels")->capture_default_str();
  truth->add_option("--threads", tr.options.threads, "worker threads (0 = all)")
      ->capture_default_str();
  truth->add_option("--camera", tr.options.camera, "index of the scene camera")
      ->capture_default_str();
  truth->add_flag("--no-cull", tr.noCull, "draw back faces of single-sided materials too");
  truth->add_option("--edges", tr.edges, "also write the edge mask (pixels an edge crosses)");

  std::string compareImage, compareReference, compareEdges;
  CLI::App* compare = app.add_subcommand(
      "compare", "RMSE and PSNR of IMAGE against REFERENCE in linear light, all and edge pixels");
  compare->add_option("image", compareImage, "PNG image")->required();
  compare->add_option("reference", compareReference, "PNG reference, e.g. from `truth`")
      ->required();
  compare->add_option("--edges", compareEdges,
                      "edge mask from `truth --edges` (default: pixels "
                      "whose neighbours differ in the reference)");

  std::string queryScene, queryFilter = "scene";
  std::vector<double> queryAt, queryLos;
  CLI::App* query = app.add_subcommand(
      "terrain", "ask a scene's terrain: the ground's height at a point, or a line of sight");
  query->add_option("scene", queryScene, "scene file with terrain")->required();
  query->add_option("--height", queryAt, "X,Y,Z: the ground under this world point")
      ->delimiter(',')
      ->expected(3);
  query->add_option("--los", queryLos, "X,Y,Z,X,Y,Z: where the segment first meets the ground")
      ->delimiter(',')
      ->expected(6);
  query->add_option("--terrain-filter", queryFilter, "scene, bilinear or bicubic")
      ->capture_default_str();

  std::string igConfig;
  sv::ig::IgRunOptions igOptions;
  bool igFast = false, igNoGovernor = false;
  CLI::App* ig = app.add_subcommand(
      "ig", "run as an image generator: a real-time frame loop driven by a CIGI 3.3 host");
  ig->add_option("config", igConfig, "the IG configuration (docs/ig.md)")->required();
  ig->add_option("--output", igOptions.output,
                 "null, png:DIR (a PNG sequence), y4m:PATH (a video stream; - for stdout), "
                 "window or window:channels (SDL2)")
      ->capture_default_str();
  ig->add_option("--frames", igOptions.frames, "stop after N frames (0: run until stopped)");
  ig->add_option("--record", igOptions.record, "write the session (both directions) as pcap");
  ig->add_option("--replay", igOptions.replay,
                 "drive the frames from a recorded session instead of the network");
  ig->add_option("--status", igOptions.status, "a JSON line a frame to FILE, or - for stdout");
  ig->add_flag("--overlay", igOptions.overlay, "draw stage times, quality level and counts");
  ig->add_option("--test-pattern", igOptions.testPattern,
                 "show grid, bars or wedges on every channel instead of the scene");
  ig->add_flag("--as-fast-as-possible", igFast, "do not wait for each frame's slot");
  ig->add_flag("--no-governor", igNoGovernor, "overload protection off (always full quality)");

  PrepArgs p;
  CLI::App* prep = app.add_subcommand(
      "prep", "prepare a database: optimize meshes, generate levels of detail, write .svdb");
  prep->add_option("input", p.input, "a scene file of any supported format, or a generator (city)")
      ->required();
  prep->add_option("-o,--output", p.output, "the prepared database (.svdb)")->required();
  prep->add_flag("--no-optimize", p.noOptimize, "keep the meshes' vertex order as it is");
  prep->add_flag("--no-lods", p.noLods, "generate no levels of detail");
  prep->add_option("--lod-levels", p.options.maxLevels,
                   "levels per generated group, the source mesh included (2 to 8)")
      ->capture_default_str();
  prep->add_option("--reduction", p.options.reduction,
                   "each generated level's triangles over the one before's")
      ->capture_default_str();
  prep->add_option("--min-triangles", p.options.minTriangles,
                   "meshes smaller than this get no generated levels")
      ->capture_default_str();
  prep->add_option("--pixel-error", p.options.pixelError,
                   "the error a level may show, in pixels of a 1080-line screen at 60°")
      ->capture_default_str();
  addGeneratorOptions(prep, p.generator);

  std::string hostScript;
  int hostIgPort = 0, hostPort = -1;
  long long hostFrames = 0;
  CLI::App* host = app.add_subcommand("host", "drive an IG with a scripted CIGI host (docs/ig.md)");
  host->add_option("script", hostScript, "the host script (JSON)")->required();
  host->add_option("--ig-port", hostIgPort, "the IG's UDP port (default: the script's)");
  host->add_option("--port", hostPort, "the host's own UDP port (default: the script's)");
  host->add_option("--frames", hostFrames, "host frames to send (default: the script's)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  if (*render) return runRender(r);
  if (*bench) {
    // BENCH.md's freeform-one is 1024 × 1024 unless the size is given.
    if (b.scene == sv::generators::generatorName(sv::generators::Generator::freeformOne) &&
        bench->count("--width") == 0 && bench->count("--height") == 0)
      b.options.width = b.options.height = 1024;
    return runBench(b);
  }
  if (*gen) return runGen(g);
  if (*truth) return runTruth(tr);
  if (*compare) return runCompare(compareImage, compareReference, compareEdges);
  if (*query) return runTerrainQuery(queryScene, queryAt, queryLos, queryFilter);
  if (*ig) {
    igOptions.realtime = !igFast;
    igOptions.governor = !igNoGovernor;
    return runIg(igConfig, igOptions);
  }
  if (*host) return runHost(hostScript, hostIgPort, hostPort, hostFrames);
  if (*prep) return runPrep(p);
  return 0;
}
