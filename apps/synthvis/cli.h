// The command-line tool's shared parts: each command is a file of its own (<command>_command.cpp)
// that adds its subcommand to the app and, when it is the one given, sets what main runs. The CLI
// parses and prints; everything else is the library's, through its public headers only.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

#include "synthvis/bench.h"
#include "synthvis/files.h"
#include "synthvis/generators.h"
#include "synthvis/render.h"
#include "synthvis/result.h"
#include "synthvis/scene.h"

namespace sv::cli {

// What the parsed command runs; its result is the process's exit status.
using Run = std::function<int()>;

// The commands, each adding its subcommand to `app` and setting `run` when it is the one given.
void addRenderCommand(CLI::App& app, Run& run);
void addBenchCommand(CLI::App& app, Run& run);
void addGenCommand(CLI::App& app, Run& run);
void addTruthCommand(CLI::App& app, Run& run);
void addCompareCommand(CLI::App& app, Run& run);
void addTerrainCommand(CLI::App& app, Run& run);
void addIgCommand(CLI::App& app, Run& run);
void addHostCommand(CLI::App& app, Run& run);
void addPrepCommand(CLI::App& app, Run& run);

// Prints "synthvis: <file>: <problem>" to standard error; returns 1, the exit status of a failure.
int fail(const Error& e);

// The scene at `path`, or the built-in demo scene when no path is given; what the file holds but
// is not drawn is printed as warnings.
Result<scene::Scene> loadSceneOrDemo(const std::string& path);

// --filter box|tent3.
Result<RenderOptions::Filter> parseFilter(const std::string& name);

using core::withSuffix;  // synthvis/files.h: out.png → out-left.png

// The segment pipeline's video channel (RenderOptions::SegmentChannel), for render and bench.
void addSegmentChannelOptions(CLI::App* app, RenderOptions& o);

// The parameters of BENCH.md's generators, shared by `bench`, `gen` and `prep`.
struct GeneratorArgs {
  generators::TrisParams tris;
  int layers = 4;
  std::string order = "random";
  int objects = 100;
  int size = 4096;  // terrain: heights a side
  std::string terrainFilter = "bilinear";
  std::string stars = "auto";  // lights: the star catalogue, "auto" or "none"
  int lights = 100000;         // lights: light points per channel, stars included
  generators::CityParams city;
  generators::VolumeParams volume;
};
void addGeneratorOptions(CLI::App* app, GeneratorArgs& g);

// The bench case for generator `kind` with the given parameters; an error names an unknown
// generator or parameter.
Result<reference::BenchCase> generatorCase(const std::string& kind, const GeneratorArgs& g);

}  // namespace sv::cli
