// The image generator (docs/ig.md): its configuration, the real-time frame loop a CIGI 3.3 host
// drives, and a scripted host to drive it — what `synthvis ig` and `synthvis host` run.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "synthvis/cigi.h"
#include "synthvis/geodesy.h"
#include "synthvis/render.h"
#include "synthvis/result.h"
#include "synthvis/scene.h"

namespace sv::cluster {
class Cluster;  // synthvis/cluster.h
}

namespace sv::ig {

// --- The configuration ---------------------------------------------------------------------
// The image generator's configuration (docs/ig.md, "Configuration"): the database, the display
// channels, the rate, the model table, the network and the quality the frame starts from.

struct IgConfig {
  std::string scene;  // the database (a scene file), relative paths from the config's folder
  double rate = 60;   // frames per second, 1 … 240
  // The channels; empty: the scene's own, or one channel of width × height.
  std::vector<scene::Channel> channels;
  int width = 1280, height = 720;
  std::map<uint16_t, std::string> models;  // CIGI entity type → model file (any scene format)
  // The database's origin on the Earth (synthvis/geodesy.h), when the configuration gives one; a
  // database with a geodetic frame of its own (Scene::geodetic) needs none, and one given must
  // be the same.
  GeoPoint origin;
  bool hasOrigin = false;
  // UDP: the IG listens on `port` (0: no network — replay, tests) and answers the host at
  // hostAddress:hostPort (or, when hostPort is 0, at whatever address last sent to it).
  uint16_t port = 8004;
  std::string hostAddress = "127.0.0.1";
  uint16_t hostPort = 8005;
  RenderOptions render;         // threads, anti-aliasing, filters: full quality
  double deadline = 0.9;        // the share of a frame period a frame may take (overload.h)
  uint16_t maxEntities = 1024;  // entity IDs 0 … maxEntities − 1
  // Under mpirun (docs/cluster.md): the channels each rank draws, by channel index — rank r draws
  // ranks[r]; empty: channel i on rank i mod N. And how long rank 0 waits at the frame lock for a
  // rank before it ends the job, naming it.
  std::vector<std::vector<int>> ranks;
  double rankTimeout = 5;
  // Channels drawn by several ranks together (synthvis/tile_share.h): each split channel's tiles
  // dealt to its ranks, the first of which assembles and presents it.
  struct Split {
    int channel = 0;
    std::vector<int> ranks;
  };
  std::vector<Split> splits;
  // A curved-screen display instead of flat channels (docs/ig.md, "A curved screen"): each of its
  // projectors is a channel, drawn pre-distorted and edge-blended as render.correction says
  // (synthvis/display.h), the test patterns and the overlay through the same correction; View
  // Control of view 0 moves its eye point. Not with `channels` or channels split among ranks.
  struct DisplayConfig {
    std::string mpcdi;                // an MPCDI file (3d profile); empty: the demo cylinder
    int width = 1920, height = 1080;  // the cylinder's projectors
    double overlapDegrees = 10;
  };
  std::optional<DisplayConfig> display;
};

// What each of `ranks` processes draws under `config` with `channelCount` channels, by rank, in
// channel order: whole channels — the configuration's assignment, or the channels not split
// dealt round the ranks (the j-th on rank j mod ranks) — and its parts of split channels (their
// exchange left for the caller). Errors: a channel on no rank or on two (assigned twice, or
// assigned and split), an index beyond the channels or the ranks, an assignment for another
// number of ranks, and a rank left with nothing to draw.
Result<std::vector<std::vector<ChannelShare>>> channelsByRank(const IgConfig& config,
                                                              int channelCount, int ranks);

// Reads a configuration file; errors name the file and the field.
Result<IgConfig> loadIgConfig(const std::string& path);
Result<IgConfig> parseIgConfig(const std::string& text, const std::string& path);

// --- The frame loop ------------------------------------------------------------------------
// `synthvis ig`: the real-time frame loop (docs/ig.md). At a fixed rate from a monotonic clock,
// each frame: take the host's datagrams that arrived (or, replaying, those recorded for this
// frame), apply them to the state (world.h), answer the host — Start of Frame with the IG's frame
// counter, and the HAT/HOT and line-of-sight responses — choose the quality the deadline allows
// (overload.h), render every channel, present them (present/), and write a status line. The state
// changes only between frames and moves by the frame period, never by the measured time, so a
// recorded session (--record: a pcap of both directions) replays to the same frames bit for bit.

struct IgRunOptions {
  std::string output =
      "null";            // a presenter spec (present/presenter.h): png:DIR, y4m:PATH, window, null
  std::string record;    // a pcap file the session is written to
  std::string replay;    // a pcap file (from --record) whose host traffic drives the frames
  std::string status;    // JSON lines, one a frame: a file, or "-" for standard output
  uint64_t frames = 0;   // stop after this many (0: until stopped, or the replay's end)
  bool overlay = false;  // per-stage times, the quality level and counts drawn on channel 0
  std::string testPattern;  // grid, bars or wedges: every channel shows it instead of the scene
  // A display whose screen is known (the cylinder): where to write, at the end, the simulated
  // viewer's view of the screen lit by the last frame's projectors (a PNG; docs/display.md).
  std::string viewer;
  bool realtime = true;     // false: frames as fast as they render (replays, tests)
  bool governor = true;     // overload protection on
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
  // The quality levels the frames were drawn at: per level (0 … the last), its name (what it gave
  // up) and how many frames.
  std::vector<std::pair<std::string, uint64_t>> levels;
  double frameMsP50 = 0, frameMsP99 = 0, frameMsMax = 0;  // the frame's work, start to presented
  double periodMsP50 = 0, periodMsP99 = 0;                // from one frame's start to the next's
  double loopMsMean = 0;  // receive, update, answer and present: everything but the render
  uint64_t datagrams = 0, malformed = 0, rejected = 0;
  uint64_t dropped = 0;         // frames a file output could not keep up with (present/present.h)
  std::string summary() const;  // several lines, for the terminal and the closing notes
};

class IgLoop {
 public:
  ~IgLoop();
  static Result<std::unique_ptr<IgLoop>> create(const IgConfig& config,
                                                const IgRunOptions& options);

  // The UDP port the IG listens on (the configuration's, or the one the system chose for 0).
  uint16_t port() const;
  // Runs until options.frames, the replay's end, a closed window or stop().
  Result<IgRunReport> run();
  // Asks a running loop to end after the frame it is drawing (any thread).
  void stop() { stop_ = true; }

 private:
  IgLoop();
  struct Impl;
  struct Session;  // one run's frames (loop.cpp)
  std::unique_ptr<Impl> impl_;
  std::atomic<bool> stop_{false};
};

// --- The scripted host ---------------------------------------------------------------------
// A scripted CIGI host (docs/ig.md, "The scripted host"): what tests, demos and users without a
// simulator drive the IG with. A script (JSON) flies the ownship and other entities along timed
// paths and, at given times, switches light groups, sets the visibility and the time of day, and
// asks for heights and lines of sight. The host answers each Start of Frame with its next frame
// (CIGI's synchronous mode): IG Control, the entities' poses at the host frame's time, and the
// events that fall due — so the IG draws host frame k at IG frame k + 1.

struct PathPoint {
  double t = 0;                         // seconds
  double lat = 0, lon = 0, alt = 0;     // degrees, degrees, metres
  double yaw = 0, pitch = 0, roll = 0;  // degrees
};

struct ScriptEntity {
  uint16_t id = 0;
  uint16_t type = 0;
  std::vector<PathPoint> path;  // by time; the pose between two points is interpolated
};

struct ScriptEvent {
  double t = 0;
  std::vector<cigi::Packet> packets;  // sent in the host frame whose time first reaches t
};

struct HostScript {
  std::string igAddress = "127.0.0.1";
  uint16_t igPort = cigi::kIgPort;
  uint16_t port = cigi::kHostPort;  // the host's own (0: any)
  double rate = 60;                 // host frames a second (the IG's rate)
  uint64_t frames = 600;
  std::vector<ScriptEntity> entities;  // entity 0 is the ownship
  std::vector<ScriptEvent> events;     // by time
};

// Reads a script; positions are "lat"/"lon"/"alt" or "east"/"north"/"up" metres from the
// script's "origin" (docs/ig.md). Errors name the file and the field.
Result<HostScript> loadHostScript(const std::string& path);
Result<HostScript> parseHostScript(const std::string& text, const std::string& path);

// The packets of host frame `frame` (time frame / rate): IG Control, every entity's pose, the
// events due since the previous frame.
std::vector<cigi::Packet> hostFrame(const HostScript& script, uint64_t frame, uint32_t lastIgFrame);

// What the IG answered.
struct HostLog {
  uint64_t framesSent = 0;
  uint64_t startOfFrames = 0;
  uint32_t lastIgFrame = 0;
  std::vector<cigi::HatHotResponse> heights;
  std::vector<cigi::LosResponse> linesOfSight;
};

// Runs the script against an IG over UDP until its frames are sent (and the IG's answers to the
// last of them have come, or `timeoutMs` passed without a Start of Frame: an error naming the IG's
// address). The first Start of Frame is waited for `startMs`: an IG loads its database and
// calibrates its governor before its first frame (seconds for a large terrain).
Result<HostLog> runHost(const HostScript& script, int timeoutMs = 2000, int startMs = 60000);

}  // namespace sv::ig
