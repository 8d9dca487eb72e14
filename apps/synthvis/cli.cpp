// The command-line tool's shared parts (cli.h).
#include "cli.h"

#include <fmt/format.h>

#include <cstdio>

#include "synthvis/formats.h"

namespace sv::cli {

int fail(const Error& e) {
  fmt::print(stderr, "synthvis: {}\n", e.str());
  return 1;
}

Result<scene::Scene> loadSceneOrDemo(const std::string& path) {
  if (path.empty()) return formats::demoScene();
  Result<scene::Scene> scene = formats::loadScene(path);
  if (scene)
    for (const std::string& w : scene->warnings) fmt::print(stderr, "synthvis: warning: {}\n", w);
  return scene;
}

Result<RenderOptions::Filter> parseFilter(const std::string& name) {
  if (name == "box") return RenderOptions::Filter::box;
  if (name == "tent3") return RenderOptions::Filter::tent3;
  return Error{"", "", fmt::format("unknown filter '{}' (box or tent3)", name)};
}

// The `render` subcommand's options, into `r`.
void addSegmentChannelOptions(CLI::App* app, RenderOptions& o) {
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

}  // namespace sv::cli
