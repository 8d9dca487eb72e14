// Based on: seed 004 (a real-time image generator: a fixed frame rate, built-in test and
// diagnostics), seed 002 (overload protection), CIGI 3.3 (the host's frame and the IG's Start of
// Frame).
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <thread>

#include "cigi/pcap.h"
#include "ig/overload.h"
#include "ig/udp.h"
#include "ig/world.h"
#include "present/overlay.h"
#include "present/present.h"
#include "present/test_patterns.h"
#include "render/correction.h"
#include "render/view_renderer.h"
#include "synthvis/cigi.h"
#include "synthvis/cluster.h"
#include "synthvis/display.h"
#include "synthvis/files.h"
#include "synthvis/ig.h"
#include "synthvis/image.h"
#include "synthvis/render.h"

namespace sv::ig {
namespace {

using Clock = std::chrono::steady_clock;

double msBetween(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t i = std::min(v.size() - 1, size_t(std::ceil(p * double(v.size()))) - (p > 0));
  return v[i];
}

// What the governor scales the polygons' and lights' estimates by: the frame's triangles and light
// points.
double geometryWork(const scene::Scene& s) {
  return double(s.triangleCount() + s.lightPoints.size());
}

// What the database's ray-cast passes give the governor to give up.
PassLevels passLevels(const scene::Scene& s) {
  PassLevels p;
  for (const scene::Terrain& terrain : s.terrains) p.terrain = true, p.bicubic |= terrain.bicubic;
  p.volumes = !s.volumes.empty();
  p.volumeWindowTolerance = s.volumeSettings.windowTolerance;
  return p;
}

// Each pixel of `image` shown r × r times in `out`, cropped to width × height (pixel
// replication): each source row expanded once, then copied r times. `out` keeps its memory from
// frame to frame (18 MB of fresh pages a frame for three 1080p channels cost more than the copy).
void replicate(const Image& image, int r, int width, int height, Image& out) {
  out.width = width;
  out.height = height;
  out.rgb.resize(size_t(width) * size_t(height) * 3);
  const size_t rowBytes = size_t(width) * 3;
  for (int sy = 0; sy * r < height; ++sy) {
    const uint8_t* src = image.pixel(0, std::min(sy, image.height - 1));
    uint8_t* row = out.pixel(0, sy * r);
    for (int x = 0; x < width; ++x)
      std::memcpy(row + 3 * x, src + 3 * std::min(x / r, image.width - 1), 3);
    for (int k = 1; k < r && sy * r + k < height; ++k)
      std::memcpy(out.pixel(0, sy * r + k), row, rowBytes);
  }
}

// A frame's input as rank 0 broadcasts it (docs/cluster.md): whether the replay has ended, the
// recorded quality level, and the host's datagrams — little-endian u8, i32, u32 count, then each
// as a u32 length and its bytes.
void packInput(bool ended, int level, const std::vector<std::vector<uint8_t>>& datagrams,
               std::vector<uint8_t>& out) {
  out.clear();
  const auto u32 = [&](uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(uint8_t(v >> (8 * i)));
  };
  out.push_back(ended ? 1 : 0);
  u32(uint32_t(level));
  u32(uint32_t(datagrams.size()));
  for (const std::vector<uint8_t>& d : datagrams) {
    u32(uint32_t(d.size()));
    out.insert(out.end(), d.begin(), d.end());
  }
}

void unpackInput(const std::vector<uint8_t>& in, bool& ended, int& level,
                 std::vector<std::vector<uint8_t>>& datagrams) {
  size_t at = 0;
  const auto u32 = [&] {
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= uint32_t(in[at++]) << (8 * i);
    return v;
  };
  ended = in[at++] != 0;
  level = int(int32_t(u32()));
  datagrams.resize(u32());
  for (std::vector<uint8_t>& d : datagrams) {
    const uint32_t n = u32();
    d.assign(in.begin() + long(at), in.begin() + long(at + n));
    at += n;
  }
}

}  // namespace

struct IgLoop::Impl {
  IgConfig config;
  IgRunOptions options;
  std::optional<IgWorld> world;
  UdpSocket socket;
  bool network = false;
  sockaddr_in host{};
  bool hostKnown = false;
  std::vector<cigi::CapturedDatagram> replay;
  size_t replayAt = 0;
  cigi::PcapWriter recorder;
  bool recording = false;
  std::unique_ptr<present::Presenter> presenter;
  std::FILE* status = nullptr;
  bool ownsStatus = false;
  std::string statusName;  // for the warning when it can no longer be written
  std::map<int, std::unique_ptr<Renderer>> renderers;  // by quality level
  // A curved screen (IgConfig::display): its projectors are the channels; at a level drawn at 1/r
  // of the size, the display at that size (its plans made on its first frame, then kept).
  std::optional<Display> display;
  std::map<int, Display> scaledDisplays;  // by r > 1
  bool loggedMalformed = false;
  // The job (docs/cluster.md): this rank's channels (all of them in a job of one).
  cluster::Cluster* cluster = nullptr;
  int rank = 0, ranks = 1;
  std::vector<ChannelShare> mine;                        // in channel order
  std::vector<std::unique_ptr<TileExchange>> exchanges;  // this rank's split channels'
  bool splits = false;                                   // some channel is drawn by several ranks

  ~Impl() {
    if (ownsStatus && status) std::fclose(status);
  }

  // A status stream that can no longer be written (a full disk, a closed pipe) is given up with
  // one warning: it is for monitoring, and the picture the simulator waits for goes on.
  void giveUpStatus(int error) {
    std::fprintf(stderr,
                 "synthvis ig: %s: cannot write the status stream: %s; no more status lines\n",
                 statusName.c_str(), core::writeFailure(error));
    if (ownsStatus) std::fclose(status);
    status = nullptr;
  }

  Renderer& rendererFor(int level, const RenderOptions& quality) {
    std::unique_ptr<Renderer>& r = renderers[level];
    if (!r) r = std::make_unique<Renderer>(quality);
    return *r;
  }

  const Display& displayAt(int replication) {
    if (replication <= 1) return *display;
    auto it = scaledDisplays.find(replication);
    if (it == scaledDisplays.end())
      it = scaledDisplays.emplace(replication, display->scaled(replication)).first;
    return it->second;
  }

  // The host datagrams for frame `frame`: those waiting on the socket, or the replay's — and then
  // the quality level the recorded frame was drawn at (its Start of Frame's IG status).
  void hostDatagrams(uint32_t frame, std::vector<std::vector<uint8_t>>& out, bool& replayEnded,
                     int& recordedLevel) {
    out.clear();
    recordedLevel = -1;
    if (!options.replay.empty()) {
      // A recording holds each frame's host datagrams, then the IG's Start of Frame for it.
      for (; replayAt < replay.size(); ++replayAt) {
        const cigi::CapturedDatagram& d = replay[replayAt];
        if (d.fromHost) {
          out.push_back(d.bytes);
          continue;
        }
        Result<cigi::Datagram> ig = cigi::parseDatagram(d.bytes);
        const auto* sof = ig ? std::get_if<cigi::StartOfFrame>(&ig->packets.front()) : nullptr;
        if (sof && sof->igFrame >= frame) {
          recordedLevel = sof->igStatus;
          ++replayAt;
          return;
        }
      }
      replayEnded = true;
      return;
    }
    if (!network) return;
    std::vector<uint8_t> bytes;
    sockaddr_in from{};
    while (socket.receive(bytes, from)) {
      if (config.hostPort == 0) {
        host = from;  // answer whoever drives us
        hostKnown = true;
      }
      out.push_back(bytes);
    }
  }
};

IgLoop::IgLoop() : impl_(std::make_unique<Impl>()) {}
IgLoop::~IgLoop() = default;

uint16_t IgLoop::port() const { return impl_->socket.port(); }

Result<std::unique_ptr<IgLoop>> IgLoop::create(const IgConfig& config,
                                               const IgRunOptions& options) {
  std::unique_ptr<IgLoop> loop(new IgLoop());
  Impl& m = *loop->impl_;
  m.config = config;
  m.options = options;
  if (Status s = validate(config.render); !s) return s.error();
  if (config.display) {
    // The display's projectors become the channels, named as they are (a file's region ids made
    // fit to name image files).
    const IgConfig::DisplayConfig& d = *config.display;
    Result<Display> display =
        d.mpcdi.empty() ? Result<Display>(Display::cylinder(d.width, d.height, d.overlapDegrees))
                        : Display::readMpcdi(d.mpcdi);
    if (!display) return display.error();
    m.display = display.value();
    m.config.channels.clear();
    for (int p = 0; p < m.display->projectorCount(); ++p) {
      scene::Channel c;
      c.name = m.display->projectorName(p);
      for (char& ch : c.name)
        if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '-' && ch != '_') ch = '_';
      if (c.name.empty()) c.name = fmt::format("projector{}", p);
      c.width = m.display->projectorWidth(p);
      c.height = m.display->projectorHeight(p);
      m.config.channels.push_back(c);
    }
  }
  Result<IgWorld> world = IgWorld::load(m.config);
  if (!world) return world.error();
  m.world.emplace(std::move(world.value()));
  m.cluster = options.cluster;
  if (m.cluster) m.rank = m.cluster->rank(), m.ranks = m.cluster->size();
  Result<std::vector<std::vector<ChannelShare>>> byRank =
      channelsByRank(m.config, int(m.world->channels().size()), m.ranks);
  if (!byRank) return byRank.error();
  m.mine = byRank.value()[size_t(m.rank)];
  // Every rank makes every split's group, in channel order (a collective step); each keeps its
  // own parts' exchanges.
  std::vector<IgConfig::Split> splits = config.splits;
  std::sort(splits.begin(), splits.end(),
            [](const auto& a, const auto& b) { return a.channel < b.channel; });
  for (const IgConfig::Split& split : splits) {
    if (split.ranks.size() < 2 || !m.cluster) continue;
    m.splits = true;
    std::unique_ptr<TileExchange> e = m.cluster->shareGroup(split.ranks, config.rankTimeout);
    for (ChannelShare& c : m.mine)
      if (c.channel == split.channel) c.tiles.exchange = e.get();
    if (e) m.exchanges.push_back(std::move(e));
  }
  if (m.rank != 0) {
    // Rank 0 alone hears the host; the others take its datagrams from the broadcast.
  } else if (!options.replay.empty()) {
    Result<std::vector<cigi::CapturedDatagram>> r = cigi::readPcap(options.replay);
    if (!r) return r.error();
    m.replay = std::move(r.value());
  } else {
    if (Status s = m.socket.open(config.port); !s) return s.error();
    m.network = true;
    if (config.hostPort != 0) {
      Result<sockaddr_in> host = udpAddress(config.hostAddress, config.hostPort);
      if (!host) return host.error();
      m.host = host.value();
      m.hostKnown = true;
    }
  }
  if (!options.record.empty() && m.rank == 0) {
    if (Status s = m.recorder.open(options.record); !s) return s.error();
    m.recording = true;
  }
  // A rank that shows nothing — only parts of split channels that another rank assembles — opens
  // no output (a y4m stream of no channels has no frame to write).
  const auto shows = [](const std::vector<ChannelShare>& shares) {
    return std::any_of(shares.begin(), shares.end(),
                       [](const ChannelShare& c) { return c.tiles.part == 0; });
  };
  const bool showsNothing = m.ranks > 1 && !shows(m.mine);
  // Where several ranks show channels, each writes its own y4m stream: PATH.rankR (ranks on one
  // machine would otherwise write one file over each other), and a pipe would interleave them.
  std::string output = options.output;
  const auto showing = std::count_if(byRank.value().begin(), byRank.value().end(), shows);
  if (showing > 1 && output.rfind("y4m:", 0) == 0) {
    if (output == "y4m:-")
      return Error{"", "",
                   fmt::format("output 'y4m:-': {} ranks show channels and their streams would "
                               "interleave on one pipe (use y4m:PATH: each rank writes PATH.rankR)",
                               showing)};
    output = fmt::format("{}.rank{}", output, m.rank);
  }
  Result<std::unique_ptr<present::Presenter>> p =
      present::makePresenter(showsNothing ? "null" : output, int(std::lround(config.rate)));
  if (!p) return p.error();
  m.presenter = std::move(p.value());
  if (!options.testPattern.empty()) {
    if (Result<present::TestPattern> t = present::parseTestPattern(options.testPattern); !t)
      return t.error();
  }
  if (!options.viewer.empty() && !(m.display && m.display->hasGeometry()))
    return Error{options.viewer, "",
                 "the simulated viewer needs a display whose screen is known (\"display\": "
                 "{\"cylinder\": …} in the configuration)"};
  if (!options.viewer.empty() && m.ranks > 1)
    return Error{options.viewer, "", "the simulated viewer sees every projector: not under MPI"};
  if (options.status == "-") {
    m.status = stdout;
    m.statusName = "standard output";
  } else if (!options.status.empty()) {
    // Each rank its own stream: FILE.rankR in a job of several.
    const std::string path =
        m.ranks > 1 ? fmt::format("{}.rank{}", options.status, m.rank) : options.status;
    m.status = std::fopen(path.c_str(), "w");
    if (!m.status) return Error{path, "", "cannot write the status stream"};
    m.ownsStatus = true;
    m.statusName = path;
  }
  return loop;
}

// One run of the loop (IgLoop::run): what lasts from frame to frame, and each frame's steps, in
// the order the file comment gives them.
struct IgLoop::Session {
  explicit Session(Impl& impl)
      : m(impl),
        world(*impl.world),
        periodMs(1000 / impl.config.rate),
        period(std::chrono::duration_cast<Clock::duration>(
            std::chrono::duration<double, std::milli>(periodMs))),
        governor(qualityLevels(impl.config.render, !world.database().lodGroups.empty(),
                               passLevels(world.database())),
                 impl.config.deadline * periodMs),
        // In a job of several, this rank's channels only, whole or its part; it presents those
        // it draws whole and the shared ones it assembles (part 0).
        only(impl.ranks > 1 ? &impl.mine : nullptr) {
    if (!m.options.testPattern.empty())
      pattern = present::parseTestPattern(m.options.testPattern).value();
    if (m.display) {
      // The frames go to the presenter encoded; the viewer (--viewer) reads them back from there.
      displayView.keepLinear = false;
      if (only)
        for (const ChannelShare& c : *only) displayView.projectors.push_back(c.channel);
      if (pattern || m.options.overlay) displayPictures();
    }
  }

  Impl& m;
  IgWorld& world;
  const double periodMs;
  const Clock::duration period;
  OverloadGovernor governor;
  const std::vector<ChannelShare>* only;
  std::optional<present::TestPattern> pattern;
  IgRunReport report;
  std::vector<double> frameMs, periodsMs, loopMs;
  std::vector<std::vector<uint8_t>> incoming;
  std::vector<cigi::Packet> replies;
  std::vector<Image> images, enlarged, mineShown;
  std::vector<FrameStats> stats;
  double ground = 0;  // the ground's share of the last frame's samples (groundShare)
  std::vector<std::string> names;
  std::vector<uint8_t> input;
  Clock::time_point t0;
  bool replayEnded = false;
  // A display's: the projectors this rank draws and the eye's offset (View Control of view 0);
  // the test pattern's frames and the overlay's place, through the correction (made once).
  DisplayView displayView;
  std::vector<Image> patternImages;
  std::optional<render::PanoramaPatch> overlayPatch;
  int overlayScale = 1;

  // The display's test pattern and overlay as pictures of the viewer's field (a panorama around
  // the eye, at the centre projector's pixel angle), each projector pixel showing the picture in
  // its own direction: straight and continuous on the screen, blended in the overlaps.
  void displayPictures() {
    const render::DisplaySetup& d = m.display->setup();
    const display::DirectionTable& centre = d.projectors[d.projectors.size() / 2].table;
    const int cx = centre.width / 2, cy = centre.height / 2;
    const double pixelDegrees =
        angleBetween(centre.directions[centre.index(cx, cy)],
                     centre.directions[centre.index(std::min(cx + 1, centre.width - 1), cy)]) *
        180 / std::numbers::pi;
    const display::PanoramaView view =
        render::displayPanorama(d, pixelDegrees > 0 ? pixelDegrees : 0.05);
    overlayScale = std::max(1, centre.height / 360);
    if (pattern) {
      const Image picture = present::testPattern(*pattern, view.width, view.height, "display");
      core::ThreadPool pool(std::max(1, m.config.render.threads));
      render::showPanorama(d, view, picture, render::gammaTableOf(m.config.render), pool,
                           patternImages);
    }
    if (m.options.overlay) {
      // Room for four lines of 72 characters, centred near the top of the field (below the
      // top edge, where the projectors' upper rows curve off the screen).
      const present::TextSize text =
          present::measureText(std::string(72, 'M') + "\n\n\n", overlayScale);
      const int w = text.width + 8 * overlayScale, h = text.height + 8 * overlayScale;
      overlayPatch = render::panoramaPatch(d, view, std::max(0, (view.width - w) / 2),
                                           std::max(2 * overlayScale, view.height / 16), w, h);
    }
  }

  // Every channel of this rank at quality `q` (level `level`): the display's projectors, or the
  // channels.
  Status renderFrame(int level, const QualityLevel& q, const scene::Scene& scene) {
    Renderer& renderer = m.rendererFor(level, q.options);
    if (!m.display) return renderer.renderChannels(scene, images, &stats, only);
    if (!scene.channels.empty()) {
      const Vec3 e = scene.channels[0].offset;
      displayView.eyeOffset[0] = e.x, displayView.eyeOffset[1] = e.y,
      displayView.eyeOffset[2] = e.z;
    }
    return renderer.renderDisplay(scene, m.displayAt(q.replication), images, &stats, nullptr,
                                  displayView);
  }

  // Whether this rank presents channel c: it draws it whole, or assembles it (part 0).
  bool drawn(size_t c) const {
    return !only || std::any_of(only->begin(), only->end(), [&](const ChannelShare& s) {
      return s.channel == int(c) && s.tiles.part == 0;
    });
  }

  // Each shown channel enlarged by pixel replication (a governor level drawn at a fraction of
  // the size): `enlarged` keeps its memory from frame to frame.
  void enlarge(int replication) {
    enlarged.resize(images.size());
    for (size_t c = 0; c < images.size(); ++c)
      if (drawn(c))
        replicate(images[c], replication, world.channels()[c].width, world.channels()[c].height,
                  enlarged[c]);
  }

  // Before the clock starts, the first frame at every quality level: once each to make the
  // renderers' threads and buffers and touch their memory (so the first timed frame is not the
  // slowest), then three rounds over all levels, whose median per level is the governor's
  // calibration — what the levels cost against each other on this machine and this database.
  // Round by round, so that a slow moment of the machine weighs on every level alike.
  Status calibrate() {
    const int levels = governor.levels();
    std::vector<std::vector<double>> times(static_cast<size_t>(levels));
    std::vector<std::vector<double>> terrainTimes(static_cast<size_t>(levels));
    std::vector<FrameWork> works(static_cast<size_t>(levels));
    for (int round = 0; round < 4; ++round)
      for (int level = 0; level < levels; ++level) {
        const QualityLevel& q = governor.at(level);
        const scene::Scene& first = world.atQuality(q.stars, q.replication);
        const Clock::time_point warm = Clock::now();
        if (Status s = renderFrame(level, q, first); !s) return s.error();
        if (q.replication > 1) enlarge(q.replication);  // the enlargements' memory too
        works[size_t(level)] = {geometryWork(world.frameScene(0)), groundShare(q)};
        if (round > 0) {
          times[size_t(level)].push_back(msBetween(warm, Clock::now()));
          terrainTimes[size_t(level)].push_back(terrainMs());
        }
      }
    for (int level = 0; level < levels; ++level) {
      const double ms = percentile(times[size_t(level)], 0.5);
      governor.calibrate(level, works[size_t(level)],
                         {ms, percentile(terrainTimes[size_t(level)], 0.5)});
      ground = works[0].terrain;
      std::fprintf(stderr, "synthvis ig: quality level %d (%s): %.2f ms a frame\n", level,
                   governor.at(level).change.c_str(), ms);
    }
    return {};
  }

  // The last frame's terrain: its pass's time over the channels drawn, and the share of their
  // samples whose rays met the ground (the governor's terrain work; the same at every level).
  double terrainMs() const {
    double ms = 0;
    for (const FrameStats& s : stats) ms += s.terrainMs;
    return ms;
  }
  double groundShare(const QualityLevel& q) const {
    double hits = 0, samples = 0;
    for (size_t c = 0; c < stats.size() && c < images.size(); ++c) {
      hits += double(stats[c].terrainHits);
      samples += double(images[c].width) * images[c].height * std::max(q.options.samples, 1);
    }
    return samples > 0 ? std::min(hits / samples, 1.0) : 0.0;
  }

  // 1. The host's datagrams, applied in the order they came; the level a replayed frame was
  // recorded at (−1: none).
  int receive(uint32_t frame, Clock::time_point start) {
    int recordedLevel = -1;
    if (m.rank == 0) m.hostDatagrams(frame, incoming, replayEnded, recordedLevel);
    if (m.ranks > 1) {  // rank 0's input to every rank: the state changes alike everywhere
      if (m.rank == 0) packInput(replayEnded, recordedLevel, incoming, input);
      if (Status s = m.cluster->broadcast(input, m.config.rankTimeout); !s)
        m.cluster->abort(fmt::format("frame {}: {}", frame, s.error().message));
      unpackInput(input, replayEnded, recordedLevel, incoming);
    }
    if (replayEnded && incoming.empty()) return recordedLevel;
    replies.clear();
    world.setFrame(frame);
    if (frame > 0) world.advance(periodMs / 1000);
    for (const std::vector<uint8_t>& bytes : incoming) {
      Result<cigi::Datagram> d = cigi::parseDatagram(bytes);
      if (!d) {
        ++world.counts().malformed;
        if (!m.loggedMalformed)
          std::fprintf(stderr,
                       "synthvis ig: a malformed datagram dropped (%s); further ones are counted, "
                       "not logged\n",
                       d.error().str().c_str());
        m.loggedMalformed = true;
        continue;
      }
      if (!std::holds_alternative<cigi::IgControl>(d->packets.front())) {
        ++world.counts().malformed;  // an IG's datagram sent to us
        continue;
      }
      if (m.recording) (void)m.recorder.add({msBetween(t0, start) / 1000, true, bytes});
      world.apply(d.value(), replies);
    }
    return recordedLevel;
  }

  // 2. The quality the deadline allows. A replay draws each frame at the level it was recorded
  // at: the governor's choice depends on the machine's timing, the frame must not.
  int chooseLevel(uint32_t frame, int recordedLevel, const FrameWork& frameWork) {
    int level = m.options.governor && !pattern ? governor.choose(frameWork) : 0;
    if (!m.options.replay.empty())
      level = recordedLevel >= 0 && recordedLevel < governor.levels() ? recordedLevel : 0;
    // The parts of a shared channel must draw it alike: with splits, every rank draws at the
    // worst level any rank chose.
    if (m.splits) {
      Result<int> worst = m.cluster->agreeMax(frame, level, m.config.rankTimeout);
      if (!worst) m.cluster->abort(worst.error().message);
      level = worst.value();
    }
    return level;
  }

  // 3. Start of Frame and the answers: the host sends its next frame on it. The IG status is the
  // quality level (0: full quality; docs/ig.md).
  cigi::StartOfFrame startOfFrame(uint32_t frame, int level, Clock::time_point start) const {
    cigi::StartOfFrame sof;
    sof.igFrame = frame;
    sof.lastHostFrame = world.lastHostFrame();
    sof.mode = world.mode();
    sof.igStatus = uint8_t(level);
    sof.timestampValid = true;
    sof.timestamp = uint32_t(std::llround(msBetween(t0, start) * 100));  // 10 µs ticks
    return sof;
  }
  void answerHost(const cigi::StartOfFrame& sof, Clock::time_point start) {
    replies.insert(replies.begin(), sof);
    const std::vector<uint8_t> answer = cigi::writeDatagram(replies);
    if (m.network && m.hostKnown) m.socket.send(answer, m.host);
    if (m.recording) (void)m.recorder.add({msBetween(t0, start) / 1000, false, answer});
  }

  // 4. The frame: every channel of this rank at `level` (or the test pattern), and what is shown
  // — the images, or with replication their enlargements.
  Result<std::vector<Image>*> draw(uint32_t frame, int level) {
    const QualityLevel& q = governor.at(level);
    const scene::Scene& scene = world.atQuality(q.stars, q.replication);
    if (pattern && m.display) {
      images = patternImages;
      stats.assign(images.size(), FrameStats{});
    } else if (pattern) {
      images.resize(scene.channels.size());
      for (size_t c = 0; c < scene.channels.size(); ++c)
        images[c] = present::testPattern(*pattern, scene.channels[c].width,
                                         scene.channels[c].height, scene.channels[c].name);
      stats.assign(images.size(), FrameStats{});
    } else {
      if (Status s = renderFrame(level, q, scene); !s) {
        if (m.splits) m.cluster->abort(fmt::format("frame {}: {}", frame, s.error().message));
        return s.error();
      }
    }
    names.clear();
    for (const scene::Channel& c : scene.channels) names.push_back(c.name);
    if (q.replication <= 1) return &images;
    enlarge(q.replication);
    return &enlarged;
  }

  // The overlay (--overlay): on channel 0, or on a display through its correction.
  void drawOverlay(uint32_t frame, int level, double renderMs, std::vector<Image>& shown) const {
    double vertex = 0, setup = 0, raster = 0, lights = 0;
    for (const FrameStats& s : stats) {
      vertex += s.vertexMs;
      setup += s.setupMs;
      raster += s.rasterMs;
      lights += s.lightsMs;
    }
    const std::string terrain = world.database().terrains.empty()
                                    ? std::string()
                                    : fmt::format("  terrain {:.1f}", terrainMs());
    const std::vector<std::string> lines = {
        fmt::format("frame {}  {:.0f} Hz  render {:.1f} ms / budget {:.1f} ms", frame,
                    m.config.rate, renderMs, governor.budgetMs()),
        fmt::format("vertex {:.1f}  setup {:.1f}  tiles {:.1f}{}  lights {:.1f} ms", vertex, setup,
                    raster, terrain, lights),
        fmt::format("level {} ({})", level, governor.at(level).change),
        fmt::format("entities {}  datagrams {}  malformed {}  missed {}", world.activeEntities(),
                    world.counts().datagrams, world.counts().malformed, report.missed)};
    if (!overlayPatch) {
      present::drawOverlay(shown[0], lines, std::max(1, shown[0].height / 360));
      return;
    }
    // What the overlay makes of black and of white: the pixels under it become v·scale + add.
    Image onBlack, onWhite;
    for (Image* layer : {&onBlack, &onWhite}) {
      layer->width = overlayPatch->width;
      layer->height = overlayPatch->height;
      layer->rgb.assign(size_t(layer->width) * size_t(layer->height) * 3,
                        layer == &onBlack ? 0 : 255);
      present::drawOverlay(*layer, lines, overlayScale);
    }
    render::overlayPatch(*overlayPatch, onBlack, onWhite, shown);
  }

  // 5. In a job of several, the frame lock — presented together, or the job ends naming the rank
  // that did not come — then Start of Frame (rank 0), and this rank's channels by their names (an
  // unnamed one by its index in the whole set). Then the channels presented.
  Status present(uint32_t frame, int level, cigi::StartOfFrame& sof, Clock::time_point start,
                 std::vector<Image>* shown) {
    if (m.ranks > 1) {
      Result<int> worst = m.cluster->frameLock({frame, level}, m.config.rankTimeout);
      if (!worst) m.cluster->abort(worst.error().str());
      sof.igStatus = uint8_t(worst.value());
      if (m.rank == 0) answerHost(sof, start);
      mineShown.clear();
      std::vector<std::string> mineNames;
      for (const ChannelShare& share : m.mine) {
        const int c = share.channel;
        if (!drawn(size_t(c))) continue;  // a part the channel's part 0 shows
        mineShown.push_back((*shown)[size_t(c)]);
        mineNames.push_back(names[size_t(c)].empty() ? fmt::format("channel{}", c)
                                                     : names[size_t(c)]);
      }
      names = std::move(mineNames);
      shown = &mineShown;
    }
    if (Status s = m.presenter->present({frame, *shown, names}); !s) return s.error();
    // Not bound to a rate, the loop waits for the writer instead of letting it drop frames.
    if (!m.options.realtime)
      if (Status s = m.presenter->flush(); !s) return s.error();
    return {};
  }

  // 6. The frame counted, and its status line (--status): one JSON object a line.
  void writeStatus(uint32_t frame, int level, double ms, double renderMs) {
    uint64_t shareBytes = 0;
    double shareMs = 0;
    for (const FrameStats& st : stats) shareBytes += st.shareBytes, shareMs += st.shareMs;
    // Milliseconds to the microsecond: what the clock resolves, and short lines.
    const auto us = [](double x) { return std::round(x * 1000) / 1000; };
    const nlohmann::ordered_json line = {{"frame", frame},
                                         {"rank", m.rank},
                                         {"time", std::round(frame / m.config.rate * 1e6) / 1e6},
                                         {"ms", us(ms)},
                                         {"renderMs", us(renderMs)},
                                         {"shareBytes", shareBytes},
                                         {"shareMs", us(shareMs)},
                                         {"budgetMs", us(governor.budgetMs())},
                                         {"level", level},
                                         {"entities", world.activeEntities()},
                                         {"datagrams", world.counts().datagrams},
                                         {"malformed", world.counts().malformed},
                                         {"rejected", world.counts().rejected},
                                         {"missed", report.missed}};
    const std::string text = line.dump() + "\n";
    errno = 0;
    if (std::fwrite(text.data(), 1, text.size(), m.status) != text.size() ||
        std::fflush(m.status) != 0)
      m.giveUpStatus(errno);
  }

  // The run's figures (IgRunReport), once the loop has ended; the viewer's view of the last
  // frame's projectors (--viewer).
  Result<IgRunReport> finish(const std::vector<Image>* lastShown) {
    if (Status s = m.presenter->flush(); !s) return s.error();
    if (!m.options.viewer.empty() && lastShown) {
      Result<Image> view =
          render::viewerImage(m.display->setup(), *lastShown, display::PanoramaView{},
                              render::gammaTableOf(m.config.render));
      if (!view) return view.error();
      if (Status s = writeImage(view.value(), m.options.viewer); !s) return s.error();
    }
    report.dropped = m.presenter->dropped();
    report.frameMsP50 = percentile(frameMs, 0.5);
    report.frameMsP99 = percentile(frameMs, 0.99);
    report.frameMsMax = frameMs.empty() ? 0 : *std::max_element(frameMs.begin(), frameMs.end());
    report.periodMsP50 = percentile(periodsMs, 0.5);
    report.periodMsP99 = percentile(periodsMs, 0.99);
    double sum = 0;
    for (double x : loopMs) sum += x;
    report.loopMsMean = loopMs.empty() ? 0 : sum / double(loopMs.size());
    report.datagrams = world.counts().datagrams;
    report.malformed = world.counts().malformed;
    report.rejected = world.counts().rejected;
    return report;
  }
};

Result<IgRunReport> IgLoop::run() {
  Session s(*impl_);
  const IgRunOptions& options = impl_->options;
  if (!s.pattern && options.governor && options.replay.empty())
    if (Status st = s.calibrate(); !st) return st.error();
  s.t0 = Clock::now();
  Clock::time_point slot = s.t0, lastStart = s.t0;
  const std::vector<Image>* lastShown = nullptr;
  for (uint32_t frame = 0; !stop_; ++frame) {
    if (options.frames && frame >= options.frames) break;
    if (options.realtime) std::this_thread::sleep_until(slot);
    const Clock::time_point start = Clock::now();
    if (frame > 0) s.periodsMs.push_back(msBetween(lastStart, start));
    lastStart = start;
    const int recordedLevel = s.receive(frame, start);  // 1
    if (s.replayEnded && s.incoming.empty()) break;
    // The coming frame's work: its triangles and lights, and the ground's share of the last
    // frame's samples (a flight changes it little from frame to frame).
    const FrameWork frameWork{geometryWork(s.world.frameScene(frame / impl_->config.rate)),
                              s.ground};
    const int level = s.chooseLevel(frame, recordedLevel, frameWork);  // 2
    cigi::StartOfFrame sof = s.startOfFrame(frame, level, start);      // 3
    // In a job of several it goes after the frame lock, once every rank has drawn the frame.
    if (impl_->ranks == 1) s.answerHost(sof, start);
    const Clock::time_point renderStart = Clock::now();
    Result<std::vector<Image>*> shown = s.draw(frame, level);  // 4
    if (!shown) return shown.error();
    lastShown = shown.value();
    const double renderMs = msBetween(renderStart, Clock::now());
    if (options.overlay && !shown.value()->empty() && (s.drawn(0) || impl_->display))
      s.drawOverlay(frame, level, renderMs, *shown.value());
    if (Status st = s.present(frame, level, sof, start, shown.value()); !st)  // 5
      return st.error();
    // 6. The deadline is the whole frame's: the governor learns what a frame costs, start to
    // shown.
    const Clock::time_point end = Clock::now();
    const double ms = msBetween(start, end);
    if (!s.pattern) {
      s.governor.record(level, frameWork, {ms, s.terrainMs()});
      s.ground = s.groundShare(s.governor.at(level));
    }
    s.frameMs.push_back(ms);
    s.loopMs.push_back(ms - renderMs);
    ++s.report.frames;
    s.report.degraded += level > 0;
    s.report.worstLevel = std::max(s.report.worstLevel, level);
    if (s.report.levels.empty())
      for (int l = 0; l < s.governor.levels(); ++l)
        s.report.levels.push_back({s.governor.at(l).change, 0});
    ++s.report.levels[size_t(level)].second;
    s.report.overruns += ms > s.governor.budgetMs();
    slot += s.period;
    if (options.realtime && end > slot) {
      // Late: this frame took its successor's slot. The schedule moves on to the next free slot;
      // no frame is queued behind.
      ++s.report.missed;
      while (slot < end) slot += s.period;
    }
    if (impl_->status) s.writeStatus(frame, level, ms, renderMs);
    if (impl_->presenter->closed()) break;
  }
  return s.finish(lastShown);
}

std::string IgRunReport::summary() const {
  std::string used;
  for (size_t l = 0; l < levels.size(); ++l)
    if (levels[l].second)
      used += fmt::format("{}{} ({}): {} frames", used.empty() ? "" : ", ", l, levels[l].first,
                          levels[l].second);
  return fmt::format(
      "{}"
      "frames {}: missed {}, over the deadline {}, degraded {} (worst level {})\n"
      "frame time p50 {:.2f} ms, p99 {:.2f} ms, max {:.2f} ms; period p50 {:.2f} ms, p99 {:.2f} ms "
      "(jitter {:.2f} ms)\n"
      "loop overhead (receive, update, answer, present) {:.3f} ms a frame\n"
      "host datagrams {}, malformed {}, packets rejected {}; frames the output dropped {}",
      used.empty() ? std::string() : "levels used: " + used + "\n", frames, missed, overruns,
      degraded, worstLevel, frameMsP50, frameMsP99, frameMsMax, periodMsP50, periodMsP99,
      periodMsP99 - periodMsP50, loopMsMean, datagrams, malformed, rejected, dropped);
}

}  // namespace sv::ig
