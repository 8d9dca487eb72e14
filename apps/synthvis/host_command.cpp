// `synthvis host SCRIPT`: drive an IG with a scripted CIGI host (docs/ig.md, "The scripted host").
#include <fmt/format.h>

#include <cmath>
#include <memory>

#include "cli.h"
#include "synthvis/ig.h"

namespace sv::cli {
namespace {

// synthvis host: the scripted host (docs/ig.md).
int runHost(const std::string& scriptPath, int igPort, int port, long long frames, double wait) {
  Result<ig::HostScript> script = ig::loadHostScript(scriptPath);
  if (!script) return fail(script.error());
  if (igPort > 0) script->igPort = uint16_t(igPort);
  if (port >= 0) script->port = uint16_t(port);
  if (frames > 0) script->frames = uint64_t(frames);
  Result<ig::HostLog> log = ig::runHost(script.value(), 2000, int(std::lround(wait * 1000)));
  if (!log) return fail(log.error());
  fmt::print("host: {} frames sent, {} Start of Frame received (last IG frame {})\n",
             log->framesSent, log->startOfFrames, log->lastIgFrame);
  for (const cigi::HatHotResponse& h : log->heights)
    fmt::print("{} {}: {}\n", h.hot ? "HOT" : "HAT", h.id,
               h.valid ? fmt::format("{:.3f} m", h.height) : std::string("no ground"));
  for (const cigi::LosResponse& l : log->linesOfSight)
    fmt::print("LOS {}: {}\n", l.id,
               l.valid ? fmt::format("blocked at {:.3f} m", l.range) : std::string("clear"));
  return 0;
}

}  // namespace

void addHostCommand(CLI::App& app, Run& run) {
  struct HostArgs {
    std::string hostScript;
    int hostIgPort = 0, hostPort = -1;
    long long hostFrames = 0;
    double wait = 60;
  };
  auto args = std::make_shared<HostArgs>();
  CLI::App* host = app.add_subcommand("host", "drive an IG with a scripted CIGI host (docs/ig.md)");
  host->add_option("script", args->hostScript, "the host script (JSON)")->required();
  host->add_option("--ig-port", args->hostIgPort, "the IG's UDP port (default: the script's)");
  host->add_option("--port", args->hostPort, "the host's own UDP port (default: the script's)");
  host->add_option("--frames", args->hostFrames, "host frames to send (default: the script's)");
  host->add_option("--wait", args->wait,
                   "seconds to wait for the IG's first Start of Frame (it loads and calibrates "
                   "first)")
      ->check(CLI::Range(0.1, 3600.0))
      ->capture_default_str();
  host->callback([&run, args] {
    run = [args] {
      return runHost(args->hostScript, args->hostIgPort, args->hostPort, args->hostFrames,
                     args->wait);
    };
  });
}

}  // namespace sv::cli
