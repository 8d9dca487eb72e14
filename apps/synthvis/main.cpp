// synthvis — command-line front end.
//
//   synthvis render [SCENE] -o out.png [--width W] [--height H] [--threads T] [--camera I]
//                   [--no-cull] [--debug-view overdraw]
//   synthvis bench SCENE [--count N] [--area A] [--depth D] [--order random|f2b|b2f]
//                  [--shade gouraud] [--width W] [--height H] [--threads T] [--frames F]
//                  [--warmup W] [--seed S] [--renderer synthvis] [--json FILE] [--image FILE]
//   (shared BENCH.md defines the scenes and the JSON fields)
//
// Errors print one line, "synthvis: <file>: <problem>", and exit with status 1 (2 for usage).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <fmt/format.h>
#include <fstream>
#include <nlohmann/json.hpp>

#include "synthvis/bench.h"
#include "synthvis/generators.h"
#include "synthvis/image.h"
#include "synthvis/render.h"
#include "synthvis/scene.h"

namespace {

int fail(const sv::Error& e) {
  fmt::print(stderr, "synthvis: {}\n", e.str());
  return 1;
}

struct RenderArgs {
  std::string scene;
  std::string output = "out.png";
  std::string debugView;
  bool noCull = false;
  sv::RenderOptions options;
};

int runRender(const RenderArgs& a) {
  sv::RenderOptions o = a.options;
  o.cullBackFaces = !a.noCull;
  if (!a.debugView.empty()) {
    if (a.debugView != "overdraw")
      return fail({"", "", fmt::format("unknown debug view '{}' (available: overdraw)", a.debugView)});
    o.debugOverdraw = true;
  }
  if (sv::Status s = sv::validate(o); !s) return fail(s.error());

  sv::scene::Scene scene;
  if (a.scene.empty()) {
    scene = sv::scene::demoScene();
  } else {
    auto loaded = sv::scene::loadScene(a.scene);
    if (!loaded) return fail(loaded.error());
    scene = std::move(loaded).value();
  }
  sv::Renderer renderer(o);
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

struct BenchArgs {
  std::string scene;
  sv::scene::TrisParams tris;
  std::string order = "random";
  std::string shade = "gouraud";
  std::string renderer = "synthvis";
  std::string json;
  std::string image;
  int frames = 10;
  int warmup = 2;
  sv::RenderOptions options{.width = 1920, .height = 1080, .threads = 2};
};

int runBench(BenchArgs a) {
  if (a.renderer != "synthvis")
    return fail({"", "", fmt::format("renderer '{}' is not available in this build (synthvis)",
                                     a.renderer)});
  if (a.shade != "gouraud")
    return fail({"", "", fmt::format("shading '{}' is not available yet (gouraud)", a.shade)});
  if (sv::Status s = sv::validate(a.options); !s) return fail(s.error());
  auto order = sv::scene::parseSubmitOrder(a.order);
  if (!order) return fail(order.error());

  nlohmann::json row;
  sv::scene::Scene scene;
  if (a.scene == "tris") {
    auto& t = a.tris;
    if (t.count < 0 || t.count > 20'000'000 || !(t.area > 0 && t.area <= 1e7) || !(t.depth >= 0))
      return fail({"", "", "tris: count must be 0…2e7, area in (0, 1e7] px, depth ≥ 0"});
    t.order = order.value();
    t.width = a.options.width;
    t.height = a.options.height;
    sv::scene::TrisStats realized;
    scene = sv::scene::generateTris(t, &realized);
    row = {{"count", t.count},         {"area", t.area},
           {"depth", t.depth},         {"order", a.order},
           {"seed", t.seed},           {"realized_mean_area", realized.meanArea},
           {"depth_complexity", realized.depthComplexity}};
    fmt::print("tris: {} triangles, mean area {:.1f} px (asked {}), depth complexity {:.2f}\n",
               t.count, realized.meanArea, t.area, realized.depthComplexity);
  } else {
    auto loaded = sv::scene::loadScene(a.scene);
    if (!loaded) return fail(loaded.error());
    scene = std::move(loaded).value();
  }

  auto timed = sv::timeFrames(scene, a.options, a.frames, a.warmup);
  if (!timed) return fail(timed.error());
  const auto& r = timed.value();
  const double tris = double(scene.triangleCount());
  const double area = a.scene == "tris" ? row["realized_mean_area"].get<double>() * tris : 0;
  row.update({{"scene", a.scene},
              {"renderer", a.renderer},
              {"width", a.options.width},
              {"height", a.options.height},
              {"threads", a.options.threads},
              {"frames", a.frames},
              {"warmup", a.warmup},
              {"shade", a.shade},
              {"aa", 0},
              {"median_ms", r.medianMs},
              {"min_ms", r.minMs},
              {"max_ms", r.maxMs},
              {"median_raster_ms", r.medianRasterMs},
              {"frame_ms", r.frameMs},
              {"triangles", scene.triangleCount()},
              {"triangles_drawn", r.stats.drawn},
              {"mtri_per_s", tris / r.medianMs / 1e3},
              {"mpix_per_s", area / r.medianMs / 1e3}});
  fmt::print("{} {}x{} {} thr: median {:.2f} ms (min {:.2f}, max {:.2f}; setup+raster {:.2f}) | "
             "{:.2f} Mtri/s | {:.0f} Mpix/s\n",
             a.renderer, a.options.width, a.options.height, a.options.threads, r.medianMs, r.minMs,
             r.maxMs, r.medianRasterMs, tris / r.medianMs / 1e3, area / r.medianMs / 1e3);
  fmt::print("last frame: {}\n", r.stats.summary());
  if (!a.image.empty())
    if (sv::Status s = sv::writeImage(r.image, a.image); !s) return fail(s.error());
  if (!a.json.empty()) {
    std::ofstream out(a.json);
    out << row.dump(2) << "\n";
    if (!out) return fail({a.json, "", "cannot write"});
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"synthvis — a real-time software image generator (recursive 2x2 subdivision)"};
  app.require_subcommand(1);

  RenderArgs r;
  CLI::App* render = app.add_subcommand("render", "render a scene to an image");
  render->add_option("scene", r.scene, "scene file (.json, .gltf, .glb, .obj); default: built-in demo");
  render->add_option("-o,--output", r.output, "output image (.png or .ppm)")->capture_default_str();
  render->add_option("--width", r.options.width, "image width in pixels")->capture_default_str();
  render->add_option("--height", r.options.height, "image height in pixels")->capture_default_str();
  render->add_option("--threads", r.options.threads, "worker threads (0 = all hardware threads)")
      ->capture_default_str();
  render->add_option("--camera", r.options.camera, "index of the scene camera to use")
      ->capture_default_str();
  render->add_flag("--no-cull", r.noCull, "draw back faces of single-sided materials too");
  render->add_option("--debug-view", r.debugView, "false-colour diagnostic image: overdraw");

  BenchArgs b;
  CLI::App* bench = app.add_subcommand("bench", "time whole frames of a benchmark scene (BENCH.md)");
  bench->add_option("scene", b.scene, "generator name (tris) or scene file")->required();
  bench->add_option("--count", b.tris.count, "tris: number of triangles")->capture_default_str();
  bench->add_option("--area", b.tris.area, "tris: mean projected area, pixels")->capture_default_str();
  bench->add_option("--depth", b.tris.depth, "tris: depth complexity (0 = whole screen)")
      ->capture_default_str();
  bench->add_option("--order", b.order, "tris: random, f2b or b2f")->capture_default_str();
  bench->add_option("--seed", b.tris.seed, "generator seed")->capture_default_str();
  bench->add_option("--shade", b.shade, "gouraud")->capture_default_str();
  bench->add_option("--width", b.options.width, "image width")->capture_default_str();
  bench->add_option("--height", b.options.height, "image height")->capture_default_str();
  bench->add_option("--threads", b.options.threads, "worker threads")->capture_default_str();
  bench->add_option("--frames", b.frames, "timed frames")->capture_default_str();
  bench->add_option("--warmup", b.warmup, "untimed frames first")->capture_default_str();
  bench->add_option("--renderer", b.renderer, "synthvis")->capture_default_str();
  bench->add_option("--json", b.json, "write the results as JSON to this file");
  bench->add_option("--image", b.image, "write the last frame to this image file");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  if (*render) return runRender(r);
  if (*bench) return runBench(b);
  return 0;
}
