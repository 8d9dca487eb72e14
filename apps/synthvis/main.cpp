// synthvis — command-line front end.
//
//   synthvis render [SCENE] -o out.png [--width W] [--height H] [--threads T] [--camera I]
//                   [--no-cull] [--debug-view overdraw]
//
// Errors print one line, "synthvis: <file>: <problem>", and exit with status 1 (2 for usage).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <fmt/format.h>

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

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  if (*render) return runRender(r);
  return 0;
}
