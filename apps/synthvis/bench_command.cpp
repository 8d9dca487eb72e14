// `synthvis bench SCENE|--suite quick|full …`: whole frames of BENCH.md's scenes timed, against
// the baselines run beside synthvis in the same process (llvmpipe, VTK), as BENCH.md defines.
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <thread>

#include "cli.h"
#include "synthvis/files.h"
#include "synthvis/image.h"

namespace sv::cli {
namespace {

namespace ref = reference;

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
  int channels = 0;                // BENCH.md --channels N (SPEC §9)
  float arc = 150;                 // … abutting in this arc, degrees
  std::string pipeline = "tiles";  // segments: as --renderer segments
  RenderOptions options{.width = 1920, .height = 1080, .threads = 2};
};

// bench --channels N --arc DEG: 0 (the classic view) … 16 channels, each under 180°.
Status checkBenchChannels(int channels, float arc) {
  if (channels < 0 || channels > int(scene::kMaxChannels))
    return Error{"", "", fmt::format("--channels {}: must be 0…{}", channels, scene::kMaxChannels)};
  if (!(arc > 0 && arc < 180.0f * float(std::max(channels, 1))))
    return Error{"", "",
                 fmt::format("--arc {}: must be more than 0 and less than 180 a channel", arc)};
  return {};
}

// Checks the arguments and resolves them into a.options and a.renderer.
Status resolve(BenchArgs& a) {
  a.options.samples = a.aa == 0 ? 1 : a.aa;
  if (a.terrainLod != "on" && a.terrainLod != "off")
    return Error{"", "", fmt::format("--terrain-lod is on or off, not '{}'", a.terrainLod)};
  a.options.terrainLod = a.terrainLod == "on";
  if (auto f = parseFilter(a.filter); !f)
    return f.error();
  else
    a.options.filter = f.value();
  if (a.shade != "gouraud" && a.shade != "textured")
    return Error{"", "", fmt::format("unknown shading '{}' (gouraud or textured)", a.shade)};
  if (auto f = scene::parseTextureFilter(a.textureFilter); !f)
    return f.error();
  else
    a.options.textureFilter = f.value();
  if (auto h = parseHsr(a.hsr); !h)
    return h.error();
  else
    a.options.hsr = h.value();
  auto pipeline = parsePipeline(a.pipeline);
  if (!pipeline) return pipeline.error();
  if (pipeline.value() == RenderOptions::Pipeline::segments) {
    if (!a.renderer.empty() && a.renderer != "segments")
      return Error{"", "", "--pipeline segments is measured against the tiles: drop --renderer"};
    a.renderer = "segments";
  }
  // The segment pipeline's options are checked as the segment renderer's.
  if (a.renderer == "segments") a.options.pipeline = RenderOptions::Pipeline::segments;
  if (Status s = validate(a.options); !s) return s.error();
  if (Status s = checkBenchChannels(a.channels, a.arc); !s) return s.error();
  if (a.scene.empty() == a.suite.empty())
    return Error{"", "", "give either a scene (a generator name or a file) or --suite quick|full"};
  if (a.renderer.empty()) a.renderer = a.suite.empty() ? "synthvis" : "both";
  if (a.renderer != "synthvis" && a.renderer != "gl" && a.renderer != "both" &&
      a.renderer != "sphere-trace" && a.renderer != "tessellated" && a.renderer != "full-detail" &&
      a.renderer != "vtk" && a.renderer != "display" && a.renderer != "segments")
    return Error{"", "",
                 fmt::format("unknown renderer '{}' (synthvis, gl, vtk, both, sphere-trace, "
                             "tessellated, full-detail, display or segments)",
                             a.renderer)};
  if (auto order = generators::parseSubmitOrder(a.generator.order); !order) return order.error();
  if (a.repeat < 1 || a.repeat > 100)
    return Error{"", "", fmt::format("--repeat {}: must be 1…100", a.repeat)};
  if (a.glAa == -1) a.glAa = a.aa >= 2 ? std::min(a.aa, 4) : 0;
  if (a.glAa != 0 && a.glAa != 2 && a.glAa != 4 && a.glAa != 8 && a.glAa != 16)
    return Error{"", "",
                 fmt::format("--gl-aa {}: the reference's samples per pixel must be 0, 2, "
                             "4, 8 or 16",
                             a.glAa)};
  return {};
}

// The cases to measure: a suite's, or one scene (a generator's, or a file).
Result<std::vector<ref::BenchCase>> casesOf(const BenchArgs& a) {
  std::vector<ref::BenchCase> cases;
  if (!a.suite.empty()) {
    auto c = ref::suiteCases(a.suite);
    if (!c) return c.error();
    cases = std::move(c).value();
  } else {
    ref::BenchCase c;
    if (generators::parseGenerator(a.scene).ok()) {
      auto g = generatorCase(a.scene, a.generator);
      if (!g) return g.error();
      c = g.value();
    } else {
      c.name = a.scene;
      c.file = a.scene;
    }
    cases.push_back(c);
  }
  return cases;
}

ref::BenchSettings settingsOf(const BenchArgs& a) {
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
  return settings;
}

// Case `c` measured a.repeat times, each repetition's summary printed and its JSON rows added to
// `rows`; the repetition the median line names.
Result<ref::CaseResult> measureCase(ref::BenchRunner& runner, const ref::BenchCase& c,
                                    const BenchArgs& a, const ref::BenchSettings& settings,
                                    nlohmann::json& rows) {
  std::vector<ref::CaseResult> repeats;
  for (int k = 0; k < a.repeat; ++k) {
    if (a.repeat > 1) fmt::print("repeat {}/{}\n", k + 1, a.repeat);
    std::fflush(stdout);
    auto r = runner.run(c);
    if (!r) {
      Error e = r.error();
      if (e.file.empty() && !c.file.empty()) e.file = c.file;
      return e;
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
    const int threads = settings.options.threads > 0
                            ? settings.options.threads
                            : int(std::max(1u, std::thread::hardware_concurrency()));
    if (settings.synthvis && cr.runs[0].stats.terrains && cr.runs[0].medianMs > 0) {
      // The terrain's rays a second a core (issue 58): the frame's sample rays over its median
      // time and the worker threads.
      const double rays = double(cr.runs[0].stats.terrainSampleRays);
      fmt::print(
          "  terrain: {:.1f} M rays/s a core ({:.2f} M rays a frame, {} threads, SIMD target {})\n",
          rays / (cr.runs[0].medianMs / 1e3) / threads / 1e6, rays / 1e6, threads,
          ref::simdTarget());
    }
    if (settings.synthvis && cr.runs[0].stats.volumeSamples && cr.runs[0].stats.volumeMs > 0) {
      // The volume pass's samples a second a core (issue 59), over the pass's own time in the
      // last frame (its tiles' CPU time: a scene's other passes left out), and a ray's samples.
      const FrameStats& s = cr.runs[0].stats;
      fmt::print(
          "  volume: {:.1f} M samples/s a core, {:.1f} samples a ray ({:.2f} M samples, {:.2f} M "
          "rays a frame; the pass {:.1f} ms; {} threads, SIMD target {})\n",
          double(s.volumeSamples) / (s.volumeMs / 1e3 * threads) / 1e6,
          double(s.volumeSamples) / double(std::max<uint64_t>(s.volumeRays, 1)),
          double(s.volumeSamples) / 1e6, double(s.volumeRays) / 1e6, s.volumeMs, threads,
          ref::simdTarget());
    }
    // A display's corrected runs say what their correction cost once (the plan, its refit for a
    // moved eye, the warp: issue 61).
    for (const ref::RendererRun& run : cr.runs)
      if (run.renderer == "subfrusta" || run.renderer == "resampled")
        fmt::print("  {}: {}\n", run.renderer, run.description);
    for (size_t ch = 0; ch < cr.runs[0].channelStats.size(); ++ch)
      fmt::print("  synthvis last frame, channel {}: {}\n", ch,
                 cr.runs[0].channelStats[ch].summary());
    if (settings.pipelines && cr.runs.size() > 1)
      fmt::print(
          "  segments last frame: {}\n"
          "  segments: {:.1f} M/s, lines repeated {} ({:.1f} %)\n",
          cr.runs[1].stats.summary(), cr.params.value("segments_per_second", 0.0) / 1e6,
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
  return std::move(repeats[median]);
}

// The last frame (--image), the JSON rows (--json) and the HTML page (--html).
Status writeOutputs(const BenchArgs& a, const std::vector<ref::CaseResult>& results,
                    const nlohmann::json& rows, const ref::BenchSettings& settings,
                    const ref::BenchRunner& runner) {
  if (!a.image.empty()) {
    // The first renderer's frame to FILE; a second renderer's beside it, FILE's stem + "-" + its
    // name (out.png → out-gl.png), for `synthvis compare`.
    const std::vector<ref::RendererRun>& runs = results.back().runs;
    if (Status s = writeImage(runs[0].image, a.image); !s) return s.error();
    if (runs.size() > 1)
      if (Status s = writeImage(runs[1].image, withSuffix(a.image, runs[1].renderer)); !s)
        return s.error();
  }
  if (!a.json.empty()) {
    // One scene on one renderer: an object (BENCH.md); otherwise a list of rows.
    const std::string text = (rows.size() == 1 ? rows[0] : rows).dump(2) + "\n";
    if (Status s = core::writeFile(a.json, {text}); !s) return s.error();
  }
  if (!a.html.empty()) {
    if (Status s = ref::writeHtml(a.html, results, settings, runner.referenceDescription()); !s)
      return s.error();
    fmt::print("html: {}/index.html\n", a.html);
  }
  return {};
}

int runBench(BenchArgs a) {
  if (Status s = resolve(a); !s) return fail(s.error());
  const Result<std::vector<ref::BenchCase>> cases = casesOf(a);
  if (!cases) return fail(cases.error());
  ref::BenchSettings settings = settingsOf(a);
  ref::BenchRunner runner(settings);
  if (settings.reference) {
    if (Status s = runner.startReference(); !s) {
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
  for (size_t i = 0; i < cases->size(); ++i) {
    const ref::BenchCase& c = cases.value()[i];
    if (cases->size() > 1) fmt::print("[{}/{}] {} …\n", i + 1, cases->size(), c.name);
    Result<ref::CaseResult> result = measureCase(runner, c, a, settings, rows);
    if (!result) return fail(result.error());
    results.push_back(std::move(result).value());
  }
  if (Status s = writeOutputs(a, results, rows, settings, runner); !s) return fail(s.error());
  return 0;
}

}  // namespace

void addBenchCommand(CLI::App& app, Run& run) {
  auto args = std::make_shared<BenchArgs>();
  BenchArgs& b = *args;
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
  bench->add_option("--pipeline", b.pipeline, "tiles, or segments: the same as --renderer segments")
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
  bench->add_flag(
      "--no-instance-cull", [&b](int64_t) { b.options.cullInstances = false; },
      "transform every instance, also those wholly outside the view");
  bench->add_flag(
      "--no-lod", [&b](int64_t) { b.options.lod = false; },
      "draw every instance at full detail (level 0) at every range");
  bench->add_flag(
      "--no-merge", [&b](int64_t) { b.options.mergeCells = false; },
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
  bench->add_option("--aa", b.aa, "synthvis: samples per pixel (" + sampleCountNames() + ")")
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
  bench
      ->add_option("--terrain-lod", b.terrainLod,
                   "terrain: on (levels of detail where a pixel spans more than a grid step) or "
                   "off (the table's own surface everywhere)")
      ->capture_default_str();
  bench
      ->add_option("--volume-window-tolerance", b.options.volumeWindowTolerance,
                   "volumes: the largest difference between a screen window's corner rays for its "
                   "pixels to be interpolated (0: every pixel cast; default: the scene's own)")
      ->check(CLI::Range(0.0f, 1.0f));
  bench
      ->add_option("--channels", b.channels,
                   "display channels: N abutting views (each --width x --height) in one frame; the "
                   "time is the whole frame's (synthvis only)")
      ->capture_default_str();
  bench->add_option("--arc", b.arc, "--channels: the arc they span, degrees")
      ->capture_default_str();
  bench->add_option("--image", b.image,
                    "write the last frame of the last scene to this image file");
  bench->callback([&run, args, bench] {
    // BENCH.md's freeform-one is 1024 × 1024 unless the size is given.
    if (args->scene == generators::generatorName(generators::Generator::freeformOne) &&
        bench->count("--width") == 0 && bench->count("--height") == 0)
      args->options.width = args->options.height = 1024;
    run = [args] { return runBench(*args); };
  });
}

}  // namespace sv::cli
