// `synthvis ig CONFIG …`: run as an image generator — the real-time frame loop a CIGI 3.3 host
// drives (docs/ig.md), alone or as one rank of an MPI job (docs/cluster.md).
#include <fmt/format.h>

#include <csignal>
#include <memory>

#include "cli.h"
#include "synthvis/cluster.h"
#include "synthvis/ig.h"

namespace sv::cli {
namespace {

// synthvis ig: the real-time loop a host drives (docs/ig.md).
int runIg(const std::string& configPath, ig::IgRunOptions options) {
  // A y4m reader that goes away is the presenter's closed(), not the end of the process.
  std::signal(SIGPIPE, SIG_IGN);
  // Under mpirun, one rank of the IG (docs/cluster.md); an error on any rank ends the whole job,
  // named, rather than leaving the others waiting for it.
  Result<std::unique_ptr<cluster::Cluster>> cluster = cluster::Cluster::join();
  if (!cluster) return fail(cluster.error());
  cluster::Cluster& job = *cluster.value();
  options.cluster = &job;
  const auto failJob = [&](Error e) {
    if (e.file.empty()) e.file = configPath;
    if (job.size() > 1) job.abort(fmt::format("{}: {}", job.name(job.rank()), e.str()));
    return fail(e);
  };
  Result<ig::IgConfig> config = ig::loadIgConfig(configPath);
  if (!config) return failJob(config.error());
  Result<std::unique_ptr<ig::IgLoop>> loop = ig::IgLoop::create(config.value(), options);
  if (!loop) return failJob(loop.error());
  if (options.replay.empty() && job.rank() == 0)
    fmt::print(stderr, "synthvis ig: {} at {:.0f} Hz, listening on UDP {}{}\n", configPath,
               config->rate, loop.value()->port(),
               job.size() > 1 ? fmt::format(", {} ranks", job.size()) : std::string());
  Result<ig::IgRunReport> report = loop.value()->run();
  if (!report) return failJob(report.error());
  fmt::print(stderr, "{}{}\n", job.size() > 1 ? job.name(job.rank()) + ": " : std::string(),
             report->summary());
  return 0;
}

}  // namespace

void addIgCommand(CLI::App& app, Run& run) {
  struct IgArgs {
    std::string igConfig;
    ig::IgRunOptions igOptions;
    bool igFast = false, igNoGovernor = false;
  };
  auto args = std::make_shared<IgArgs>();
  CLI::App* ig = app.add_subcommand(
      "ig", "run as an image generator: a real-time frame loop driven by a CIGI 3.3 host");
  ig->add_option("config", args->igConfig, "the IG configuration (docs/ig.md)")->required();
  ig->add_option("--output", args->igOptions.output,
                 "null, png:DIR (a PNG sequence), y4m:PATH (a video stream; - for stdout), "
                 "window or window:channels (SDL2)")
      ->capture_default_str();
  ig->add_option("--frames", args->igOptions.frames, "stop after N frames (0: run until stopped)");
  ig->add_option("--record", args->igOptions.record, "write the session (both directions) as pcap");
  ig->add_option("--replay", args->igOptions.replay,
                 "drive the frames from a recorded session instead of the network");
  ig->add_option("--status", args->igOptions.status,
                 "a JSON line a frame to FILE, or - for stdout");
  ig->add_flag("--overlay", args->igOptions.overlay, "draw stage times, quality level and counts");
  ig->add_option("--viewer", args->igOptions.viewer,
                 "a cylinder display: write the simulated viewer's view of the last frame here");
  ig->add_option("--test-pattern", args->igOptions.testPattern,
                 "show grid, bars or wedges on every channel instead of the scene");
  ig->add_flag("--as-fast-as-possible", args->igFast, "do not wait for each frame's slot");
  ig->add_flag("--no-governor", args->igNoGovernor,
               "overload protection off (always full quality)");
  ig->callback([&run, args] {
    run = [args] {
      ig::IgRunOptions options = args->igOptions;
      options.realtime = !args->igFast;
      options.governor = !args->igNoGovernor;
      return runIg(args->igConfig, options);
    };
  });
}

}  // namespace sv::cli
