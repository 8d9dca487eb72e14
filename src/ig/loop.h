// `synthvis ig`: the real-time frame loop (docs/ig.md). At a fixed rate from a monotonic clock,
// each frame: take the host's datagrams that arrived (or, replaying, those recorded for this
// frame), apply them to the state (world.h), answer the host — Start of Frame with the IG's frame
// counter, and the HAT/HOT and line-of-sight responses — choose the quality the deadline allows
// (overload.h), render every channel, present them (present/), and write a status line. The state
// changes only between frames and moves by the frame period, never by the measured time, so a
// recorded session (--record: a pcap of both directions) replays to the same frames bit for bit.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ig/config.h"
#include "synthvis/result.h"

namespace sv::cluster {
class Cluster;
}

namespace sv::ig {

struct IgRunOptions {
  std::string output = "null";  // a presenter spec (present/presenter.h): png:DIR, y4m:PATH, window, null
  std::string record;           // a pcap file the session is written to
  std::string replay;           // a pcap file (from --record) whose host traffic drives the frames
  std::string status;           // JSON lines, one a frame: a file, or "-" for standard output
  uint64_t frames = 0;          // stop after this many (0: until stopped, or the replay's end)
  bool overlay = false;         // per-stage times, the quality level and counts drawn on channel 0
  std::string testPattern;      // grid, bars or wedges: every channel shows it instead of the scene
  bool realtime = true;         // false: frames as fast as they render (replays, tests)
  bool governor = true;         // overload protection on
  // Under mpirun, the job this process is a rank of (docs/cluster.md): rank 0 alone speaks to
  // the host (or reads the replay) and broadcasts each frame's datagrams; every rank draws and
  // presents its channels (IgConfig::ranks); the frame lock releases them together, and Start of
  // Frame goes to the host after it, with the worst quality level of all ranks. Null, or a job
  // of one: this process is the whole IG.
  cluster::Cluster* cluster = nullptr;
};

// What a run did.
struct IgRunReport {
  uint64_t frames = 0;
  uint64_t missed = 0;    // frames that ended after their slot (the next frame's start)
  uint64_t overruns = 0;  // frames that ended after their deadline
  uint64_t degraded = 0;  // frames drawn below full quality
  int worstLevel = 0;
  double frameMsP50 = 0, frameMsP99 = 0, frameMsMax = 0;  // the frame's work, start to presented
  double periodMsP50 = 0, periodMsP99 = 0;                // from one frame's start to the next's
  double loopMsMean = 0;  // receive, update, answer and present: everything but the render
  uint64_t datagrams = 0, malformed = 0, rejected = 0;
  uint64_t dropped = 0;  // frames a file output could not keep up with (present/present.h)
  std::string summary() const;  // several lines, for the terminal and the closing notes
};

class IgLoop {
 public:
  ~IgLoop();
  static Result<std::unique_ptr<IgLoop>> create(const IgConfig& config, const IgRunOptions& options);

  // The UDP port the IG listens on (the configuration's, or the one the system chose for 0).
  uint16_t port() const;
  // Runs until options.frames, the replay's end, a closed window or stop().
  Result<IgRunReport> run();
  // Asks a running loop to end after the frame it is drawing (any thread).
  void stop() { stop_ = true; }

 private:
  IgLoop();
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::atomic<bool> stop_{false};
};

}  // namespace sv::ig
