// `synthvis truth [SCENE] -o truth.png --samples 256`: the ground-truth image, brute force
// (synthvis/ground_truth.h), that anti-aliasing is measured by.
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "cli.h"
#include "synthvis/ground_truth.h"
#include "synthvis/image.h"

namespace sv::cli {
namespace {

struct TruthArgs {
  std::string scene;
  std::string output = "truth.png";
  std::string edges;
  int samples = 256;
  bool noCull = false;
  RenderOptions options;
};

int runTruth(const TruthArgs& a) {
  const int side = int(std::lround(std::sqrt(double(a.samples))));
  if (side < 1 || side > 32 || side * side != a.samples)
    return fail({"", "", fmt::format("--samples {}: must be a square from 1 to 1024", a.samples)});
  reference::GroundTruthOptions g;
  g.options = a.options;
  g.options.cullBackFaces = !a.noCull;
  g.samplesPerSide = side;
  auto loaded = loadSceneOrDemo(a.scene);
  if (!loaded) return fail(loaded.error());
  const scene::Scene scene = std::move(loaded).value();
  fmt::print("{}: {}x{}, {} samples per pixel…\n", a.output, g.options.width, g.options.height,
             a.samples);
  std::fflush(stdout);
  Image edges;
  auto image = reference::renderGroundTruth(scene, g, &edges);
  if (!image) return fail(image.error());
  if (Status s = writeImage(image.value(), a.output); !s) return fail(s.error());
  if (!a.edges.empty())
    if (Status s = writeImage(edges, a.edges); !s) return fail(s.error());
  return 0;
}

}  // namespace

void addTruthCommand(CLI::App& app, Run& run) {
  auto args = std::make_shared<TruthArgs>();
  TruthArgs& tr = *args;
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
  truth->callback([&run, args] { run = [args] { return runTruth(*args); }; });
}

}  // namespace sv::cli
