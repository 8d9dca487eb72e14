// `synthvis prep INPUT|city -o DB.svdb`: the database preparation system (docs/prep.md).
#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "cli.h"
#include "synthvis/formats.h"
#include "synthvis/prep.h"

namespace sv::cli {
namespace {

struct PrepArgs {
  std::string input;
  std::string output;
  GeneratorArgs generator;
  bool noOptimize = false, noLods = false;
  prep::PrepOptions options;
};

// `synthvis prep INPUT -o DB.svdb`: the database preparation system (docs/prep.md). INPUT is any
// scene file, or the name of a BENCH.md generator (city).
int runPrep(const PrepArgs& a) {
  using Clock = std::chrono::steady_clock;
  auto seconds = [](Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
  };
  auto t0 = Clock::now();
  Result<scene::Scene> loaded = Error{"", "", ""};
  if (generators::parseGenerator(a.input).ok()) {
    auto c = generatorCase(a.input, a.generator);
    if (!c) return fail(c.error());
    auto made = reference::makeScene(c.value(), RenderOptions{});
    if (!made) return fail(made.error());
    loaded = std::move(made.value().scene);
  } else {
    loaded = loadSceneOrDemo(a.input);
  }
  if (!loaded) return fail(loaded.error());
  scene::Scene scene = std::move(loaded).value();
  fmt::print("prep: read {} in {:.2f} s: {} meshes, {} instances, {} triangles over them\n",
             a.input, seconds(t0), scene.meshes.size(), scene.instances.size(),
             scene.triangleCount());
  prep::PrepOptions o = a.options;
  o.optimize = !a.noOptimize;
  o.generateLods = !a.noLods;
  t0 = Clock::now();
  auto report = prep::prepare(scene, o, [](size_t done, size_t total) {
    fmt::print(stderr, "\rprep: meshes {}/{}", done, total);
    if (done == total) fmt::print(stderr, "\n");
  });
  if (!report) return fail(report.error());
  fmt::print("prep: prepared in {:.2f} s: {}\n", seconds(t0), report->summary());
  t0 = Clock::now();
  if (Status s = formats::saveDatabase(scene, a.output); !s) return fail(s.error());
  const double written = seconds(t0);
  // The load time a user of the database will see: mapped, checked, copied out.
  t0 = Clock::now();
  auto back = formats::loadDatabase(a.output);
  if (!back) return fail(back.error());
  const double load = seconds(t0);
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(a.output, ec);
  fmt::print("prep: wrote {} ({:.1f} MB) in {:.2f} s; it loads in {:.1f} ms\n", a.output,
             double(bytes) / 1e6, written, load * 1e3);
  return 0;
}

}  // namespace

void addPrepCommand(CLI::App& app, Run& run) {
  auto args = std::make_shared<PrepArgs>();
  PrepArgs& p = *args;
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
  prep->callback([&run, args] { run = [args] { return runPrep(*args); }; });
}

}  // namespace sv::cli
