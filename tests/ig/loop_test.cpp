// The running IG over loopback UDP, driven by the scripted host (ig/loop.h, ig/host.h): entities
// appear in the frame after the host sends them, Start of Frame counts on, heights come back,
// bad datagrams are counted and dropped while the loop keeps its rate, a recorded session replays
// to the same frames, and overload protection holds the rate of a scene too heavy for it.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <set>
#include <thread>

#include "cigi/pcap.h"
#include "ig/geo.h"
#include "support/temp_dir.h"
#include "synthvis/cigi.h"
#include "synthvis/ig.h"
#include "synthvis/image.h"

namespace sv::ig {
namespace {

namespace fs = std::filesystem;
const std::string kConfig = std::string(SV_TEST_DATA_DIR) + "/ig/ig.json";

fs::path freshDir(const std::string& name) {
  const fs::path d =
      fs::temp_directory_path() / ("sv-ig-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

IgConfig config() {
  Result<IgConfig> c = loadIgConfig(kConfig);
  EXPECT_TRUE(c.ok()) << c.error().str();
  return c.value();
}

// The frame's PNG (present/'s png: naming, one channel "0").
fs::path framePath(const fs::path& dir, uint32_t frame) {
  char name[64];
  std::snprintf(name, sizeof name, "frame-%06u-0.png", frame);
  return dir / name;
}
Image frameImage(const fs::path& dir, uint32_t frame) {
  Result<Image> image = readPng(framePath(dir, frame).string());
  EXPECT_TRUE(image.ok()) << image.error().str();
  return image.ok() ? image.value() : Image{};
}

// The live run's frames equal the replay's, byte for byte. A live frame its PNG writer dropped
// (present/present.h: a busy writer drops rather than hold up the loop, as it may on a loaded
// machine) has nothing to compare; the replay, not in real time, writes every frame.
void expectSameFrames(const fs::path& live, const fs::path& replayed, uint32_t count) {
  uint32_t compared = 0;
  for (uint32_t f = 0; f < count; ++f) {
    EXPECT_TRUE(fs::exists(framePath(replayed, f))) << "frame " << f;
    if (!fs::exists(framePath(live, f))) continue;
    ASSERT_EQ(frameImage(live, f).rgb, frameImage(replayed, f).rgb) << "frame " << f;
    ++compared;
  }
  EXPECT_GT(compared, count / 2);
}

// A command's standard output (tshark is installed by scripts/lib.sh).
std::string shell(const std::string& command) {
  std::string out;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return "popen failed";
  char buffer[4096];
  size_t n;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) out.append(buffer, n);
  ::pclose(pipe);
  return out;
}

size_t redPixels(const Image& image) {
  size_t n = 0;
  for (size_t i = 0; i + 2 < image.rgb.size(); i += 3)
    n += image.rgb[i] > 200 && image.rgb[i + 1] < 60 && image.rgb[i + 2] < 60;
  return n;
}

// The ownship 50 m up at the origin looking north; entity 1 (the red box) is created by an event
// at `appear` seconds, 150 m ahead.
HostScript script(uint16_t igPort, uint64_t frames, double appear) {
  const GeoPoint o = config().origin;
  HostScript s;
  s.igPort = igPort;
  s.port = 0;
  s.rate = 50;
  s.frames = frames;
  ScriptEntity own;
  own.id = 0;
  own.path.push_back({0, o.lat, o.lon, 50, 0, 0, 0});
  s.entities.push_back(own);
  const GeoFrame frame(o);
  const GeoPoint ahead = frame.toGeodetic({0, 50, -150});
  cigi::EntityControl box;
  box.entity = 1;
  box.type = 7;
  box.latOrX = ahead.lat;
  box.lonOrY = ahead.lon;
  box.altOrZ = ahead.alt;
  s.events.push_back({appear, {box}});
  const GeoPoint hill = frame.toGeodetic({30, 100, -150});
  cigi::HatHotRequest hat;
  hat.id = 21;
  hat.latOrX = hill.lat;
  hat.lonOrY = hill.lon;
  hat.altOrZ = hill.alt;
  s.events.push_back({0.1, {hat}});
  return s;
}

struct Session {
  IgRunReport report;
  HostLog host;
};

// An IG of configuration `c` driven by the script `scriptFor` makes for its port, to the script's
// end.
Session runSession(const IgConfig& c, const IgRunOptions& options,
                   const std::function<HostScript(uint16_t port)>& scriptFor) {
  Result<std::unique_ptr<IgLoop>> loop = IgLoop::create(c, options);
  EXPECT_TRUE(loop.ok()) << loop.error().str();
  Session s;
  std::optional<Result<IgRunReport>> report;
  std::thread ig([&] { report.emplace(loop.value()->run()); });
  Result<HostLog> host = runHost(scriptFor(loop.value()->port()));
  loop.value()->stop();
  ig.join();
  EXPECT_TRUE(host.ok()) << host.error().str();
  EXPECT_TRUE(report->ok()) << report->error().str();
  if (host.ok()) s.host = host.value();
  if (report->ok()) s.report = report->value();
  return s;
}

Session runSession(const IgRunOptions& options, uint64_t hostFrames, double appear) {
  return runSession(config(), options,
                    [&](uint16_t port) { return script(port, hostFrames, appear); });
}

TEST(IgLoop, HostDrivenEntitiesAppearInTheNextFrameAndTheSessionReplaysBitForBit) {
  const fs::path frames = freshDir("frames"), again = freshDir("replay");
  const fs::path capture = frames / "session.pcap";
  IgRunOptions options;
  options.output = "png:" + frames.string();
  options.record = capture.string();
  const Session s = runSession(options, 30, 0.3);
  EXPECT_EQ(s.host.framesSent, 30u);
  EXPECT_GE(s.host.startOfFrames, 31u);
  // The height the host asked for, answered from the terrain.
  ASSERT_EQ(s.host.heights.size(), 1u);
  EXPECT_EQ(s.host.heights[0].id, 21);
  EXPECT_TRUE(s.host.heights[0].valid);
  EXPECT_GT(s.host.heights[0].height, 0);

  // The recording: each frame's host datagrams, then that frame's Start of Frame.
  Result<std::vector<cigi::CapturedDatagram>> rec = cigi::readPcap(capture.string());
  ASSERT_TRUE(rec.ok()) << rec.error().str();
  uint32_t expectFrame = 0, appliedAt = 0, sentAfter = 0;
  bool found = false;
  uint32_t lastHostFrame = 0;
  for (const cigi::CapturedDatagram& d : rec.value()) {
    Result<cigi::Datagram> p = cigi::parseDatagram(d.bytes);
    ASSERT_TRUE(p.ok()) << p.error().str();
    if (!d.fromHost) {
      const auto& sof = std::get<cigi::StartOfFrame>(p->packets.front());
      EXPECT_EQ(sof.igFrame, expectFrame++);  // the counter advances a frame at a time
      EXPECT_GE(sof.lastHostFrame, lastHostFrame);
      lastHostFrame = sof.lastHostFrame;
      continue;
    }
    if (found) continue;
    for (const cigi::Packet& packet : p->packets)
      if (const auto* e = std::get_if<cigi::EntityControl>(&packet); e && e->entity == 1) {
        found = true;
        appliedAt = expectFrame;  // the Start of Frame that follows is the frame it is drawn in
        sentAfter = std::get<cigi::IgControl>(p->packets.front()).lastIgFrame;
      }
  }
  ASSERT_TRUE(found);
  ASSERT_GT(appliedAt, 0u);
  EXPECT_LE(appliedAt - sentAfter, 1u) << "latency in frames";
  EXPECT_EQ(redPixels(frameImage(frames, appliedAt - 1)), 0u);
  EXPECT_GT(redPixels(frameImage(frames, appliedAt)), 200u);

  // An independent decoder agrees: Wireshark's CIGI dissector reads the whole recorded session —
  // both directions — with no malformed packet, the IG's frame counter 0, 1, 2, …, the host's
  // entity and the height the host was told.
  const std::string tshark =
      "tshark -n -r '" + capture.string() + "' -d udp.port==8004,cigi -d udp.port==8005,cigi";
  EXPECT_EQ(shell(tshark + " -Y '_ws.malformed || _ws.expert.severity >= error' 2>/dev/null"), "");
  const std::string sofs =
      shell(tshark + " -Y cigi.sof -T fields -e cigi.sof.ig_frame_number 2>/dev/null");
  std::string counting;
  for (uint32_t f = 0; f < expectFrame; ++f) counting += std::to_string(f) + "\n";
  EXPECT_EQ(sofs, counting);
  EXPECT_NE(shell(tshark + " -Y 'cigi.entity_control.entity_id == 1' -T fields -e frame.number "
                           "2>/dev/null"),
            "");
  const std::string height = shell(tshark +
                                   " -Y cigi.hat_hot_response -T fields -e "
                                   "cigi.hat_hot_response.height 2>/dev/null");
  EXPECT_NEAR(std::stod(height.empty() ? "nan" : height), s.host.heights[0].height, 1e-6) << height;

  // Replayed from the capture, as fast as it renders: the same frames, byte for byte.
  IgRunOptions replay;
  replay.output = "png:" + again.string();
  replay.replay = capture.string();
  replay.realtime = false;
  Result<std::unique_ptr<IgLoop>> loop = IgLoop::create(config(), replay);
  ASSERT_TRUE(loop.ok()) << loop.error().str();
  Result<IgRunReport> r = loop.value()->run();
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_EQ(r->frames, uint64_t(expectFrame));
  expectSameFrames(frames, again, expectFrame);
  fs::remove_all(frames);
  fs::remove_all(again);
}

// The governor's choice depends on the machine's timing; a replay must not. Recorded at a rate no
// frame can keep (so the quality falls), replayed where every frame would fit at full quality:
// each frame at its recorded level (Start of Frame's IG status), byte for byte.
TEST(IgLoop, TheReplayDrawsEachFrameAtItsRecordedQuality) {
  const fs::path frames = freshDir("levels"), again = freshDir("levels-replay");
  const fs::path capture = frames / "session.pcap";
  IgConfig c = config();
  c.rate = 240;
  c.deadline = 0.1;  // 0.42 ms a frame
  c.render.samples = 4;
  IgRunOptions options;
  options.output = "png:" + frames.string();
  options.record = capture.string();
  options.frames = 12;
  Result<std::unique_ptr<IgLoop>> loop = IgLoop::create(c, options);
  ASSERT_TRUE(loop.ok()) << loop.error().str();
  ASSERT_TRUE(loop.value()->run().ok());
  Result<std::vector<cigi::CapturedDatagram>> rec = cigi::readPcap(capture.string());
  ASSERT_TRUE(rec.ok()) << rec.error().str();
  std::set<int> levels;
  for (const cigi::CapturedDatagram& d : rec.value())
    if (!d.fromHost)
      levels.insert(
          std::get<cigi::StartOfFrame>(cigi::parseDatagram(d.bytes)->packets.front()).igStatus);
  ASSERT_FALSE(levels.empty());
  EXPECT_GT(*levels.rbegin(), 0);  // frames were drawn below full quality
  // Replayed where every frame would fit at full quality (1 Hz): still each at its recorded level.
  c.rate = 1;
  c.deadline = 1;
  IgRunOptions replay;
  replay.output = "png:" + again.string();
  replay.replay = capture.string();
  replay.realtime = false;
  Result<std::unique_ptr<IgLoop>> second = IgLoop::create(c, replay);
  ASSERT_TRUE(second.ok()) << second.error().str();
  Result<IgRunReport> r = second.value()->run();
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->frames, 12u);
  expectSameFrames(frames, again, 12);
  fs::remove_all(frames);
  fs::remove_all(again);
}

// The frame's PNG of a named channel (a display's projector).
Image projectorImage(const fs::path& dir, uint32_t frame, const std::string& name) {
  char file[96];
  std::snprintf(file, sizeof file, "frame-%06u-%s.png", frame, name.c_str());
  Result<Image> image = readPng((dir / file).string());
  EXPECT_TRUE(image.ok()) << image.error().str();
  return image.ok() ? image.value() : Image{};
}

// The IG tests' configuration on the demo cylinder: three projectors of 128 × 80.
IgConfig cylinderConfig() {
  IgConfig c = config();
  c.channels.clear();
  c.display = IgConfig::DisplayConfig{"", 128, 80, 10};
  return c;
}

// Issue 61: on a curved screen the projectors are the channels, drawn through the correction;
// View Control of view 0 moves the eye the correction is made for; the session replays bit for
// bit; the overlay is laid over the top of the field through the correction.
TEST(IgLoop, ACurvedScreensProjectorsAreTheChannelsAndAMovedEyeReplaysBitForBit) {
  const fs::path frames = freshDir("display"), again = freshDir("display-replay");
  const fs::path capture = frames / "session.pcap";
  IgRunOptions options;
  options.output = "png:" + frames.string();
  options.record = capture.string();
  const Session session = runSession(cylinderConfig(), options, [](uint16_t port) {
    HostScript sc = script(port, 20, 100);  // no box this session
    cigi::ViewControl vc;
    vc.view = 0;
    vc.entity = 0;
    vc.enable = 1 | 2 | 4;
    vc.x = 0.3f, vc.y = 0.2f, vc.z = -0.8f;  // forward, right and up, metres
    sc.events.push_back({0.2, {vc}});
    return sc;
  });
  const uint64_t drawn = session.report.frames;
  ASSERT_GE(drawn, 20u);
  // Three projectors a frame at their own size; the eye's move changes the centre one's view of
  // the ground.
  const Image first = projectorImage(frames, 1, "centre"),
              last = projectorImage(frames, 19, "centre");
  ASSERT_EQ(first.width, 128);
  ASSERT_EQ(first.height, 80);
  EXPECT_EQ(projectorImage(frames, 1, "left").width, 128);
  EXPECT_EQ(projectorImage(frames, 1, "right").width, 128);
  int moved = 0;
  for (int y = first.height / 2; y < first.height; ++y)
    for (int x = 0; x < first.width; ++x)
      moved += std::memcmp(first.pixel(x, y), last.pixel(x, y), 3) != 0;
  EXPECT_GT(moved, first.width * first.height / 50) << "the moved eye shows";

  IgRunOptions replay;
  replay.output = "png:" + again.string();
  replay.replay = capture.string();
  replay.realtime = false;
  replay.viewer = (again / "viewer.png").string();
  Result<std::unique_ptr<IgLoop>> second = IgLoop::create(cylinderConfig(), replay);
  ASSERT_TRUE(second.ok()) << second.error().str();
  Result<IgRunReport> r = second.value()->run();
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_EQ(r->frames, drawn);
  // The simulated viewer's view of the last frame: the lit screen, black beyond it.
  Result<Image> viewer = readPng(replay.viewer);
  ASSERT_TRUE(viewer.ok()) << viewer.error().str();
  size_t lit = 0;
  for (uint8_t v : viewer->rgb) lit += v > 20;
  EXPECT_GT(lit, viewer->rgb.size() / 10);
  EXPECT_EQ(viewer->pixel(0, viewer->height / 2)[0], 0) << "azimuth -100°: beyond the screen";
  uint32_t compared = 0;
  for (uint32_t f = 0; f < drawn; ++f)
    for (const char* name : {"left", "centre", "right"}) {
      char file[96];
      std::snprintf(file, sizeof file, "frame-%06u-%s.png", f, name);
      if (!fs::exists(frames / file)) continue;  // a frame the live run's writer dropped
      ASSERT_EQ(projectorImage(frames, f, name).rgb, projectorImage(again, f, name).rgb)
          << "frame " << f << " " << name;
      ++compared;
    }
  EXPECT_GT(compared, drawn * 3 / 2);
  // The same replay's first frames with the overlay: a dark box with text over the top of the
  // field, the rest of the frame as it was.
  const fs::path overlaid = freshDir("display-overlay");
  replay.output = "png:" + overlaid.string();
  replay.viewer.clear();
  replay.overlay = true;
  replay.frames = 2;
  Result<std::unique_ptr<IgLoop>> third = IgLoop::create(cylinderConfig(), replay);
  ASSERT_TRUE(third.ok()) << third.error().str();
  ASSERT_TRUE(third.value()->run().ok());
  const Image plain = projectorImage(again, 1, "centre"),
              over = projectorImage(overlaid, 1, "centre");
  int changed = 0, changedLow = 0;
  for (int y = 0; y < plain.height; ++y)
    for (int x = 0; x < plain.width; ++x)
      if (std::memcmp(plain.pixel(x, y), over.pixel(x, y), 3) != 0) {
        ++changed;
        changedLow += y >= plain.height * 3 / 4;
      }
  EXPECT_GT(changed, plain.width * plain.height / 10) << "the overlay is drawn";
  EXPECT_EQ(changedLow, 0) << "the overlay stays at the top of the field";
  fs::remove_all(frames);
  fs::remove_all(again);
  fs::remove_all(overlaid);
}

// The test pattern through the correction: one picture of the viewer's field across the
// projectors — the grid's vertical centre line on the centre projector alone, its horizontal
// one across all three (a pattern per channel would draw a centre cross on each).
TEST(IgLoop, ACurvedScreensTestPatternSpansTheProjectorsAsOnePicture) {
  const fs::path frames = freshDir("display-grid");
  IgRunOptions options;
  options.output = "png:" + frames.string();
  options.frames = 1;
  options.realtime = false;
  options.testPattern = "grid";
  Result<std::unique_ptr<IgLoop>> loop = IgLoop::create(cylinderConfig(), options);
  ASSERT_TRUE(loop.ok()) << loop.error().str();
  ASSERT_TRUE(loop.value()->run().ok());
  for (const char* name : {"left", "centre", "right"}) {
    const Image image = projectorImage(frames, 0, name);
    int top = image.height, bottom = -1, yellow = 0;
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) {
        const uint8_t* p = image.pixel(x, y);
        if (p[0] > 90 && p[1] > 90 && p[2] < 40) {
          top = std::min(top, y), bottom = std::max(bottom, y);
          ++yellow;
        }
      }
    EXPECT_GT(yellow, 20) << name;
    if (std::string(name) == "centre")
      EXPECT_GT(bottom - top, image.height / 2) << "the vertical line";
    else
      EXPECT_LT(bottom - top, 8) << name << ": the horizontal line alone";
  }
  fs::remove_all(frames);
}

// --status: a JSON line a frame. A stream that cannot be written (here a full disk) is given up
// with one warning, and the frames go on.
TEST(IgLoop, TheStatusStreamHasALineAFrameAndAFullDiskEndsItNotTheLoop) {
  IgRunOptions options;
  options.frames = 3;
  options.realtime = false;
  options.status = sv::tests::processTemp().path("status.jsonl");
  {
    Result<std::unique_ptr<IgLoop>> loop = IgLoop::create(config(), options);
    ASSERT_TRUE(loop.ok()) << loop.error().str();
    ASSERT_TRUE(loop.value()->run().ok());
  }
  std::ifstream in(options.status);
  std::string line;
  uint32_t frame = 0;
  for (; std::getline(in, line); ++frame)
    EXPECT_EQ(line.rfind("{\"frame\":" + std::to_string(frame) + ",", 0), 0u) << line;
  EXPECT_EQ(frame, 3u);

  options.status = sv::tests::fullDiskPath("full-status.jsonl");
  if (options.status.empty()) GTEST_SKIP() << "no /dev/full here";
  Result<std::unique_ptr<IgLoop>> loop = IgLoop::create(config(), options);
  ASSERT_TRUE(loop.ok()) << loop.error().str();
  testing::internal::CaptureStderr();
  Result<IgRunReport> r = loop.value()->run();
  const std::string warnings = testing::internal::GetCapturedStderr();
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_EQ(r->frames, 3u);
  const std::string warning = "synthvis ig: " + options.status +
                              ": cannot write the status stream: No space left on device; no more "
                              "status lines\n";
  EXPECT_NE(warnings.find(warning), std::string::npos) << warnings;
  EXPECT_EQ(warnings.find(warning), warnings.rfind(warning)) << "warned once";
}

TEST(IgLoop, BadDatagramsAreCountedAndDroppedAndTheLoopKeepsItsRate) {
  IgConfig c = config();
  IgRunOptions options;
  options.frames = 40;
  Result<std::unique_ptr<IgLoop>> loop = IgLoop::create(c, options);
  ASSERT_TRUE(loop.ok()) << loop.error().str();
  std::optional<Result<IgRunReport>> report;
  std::thread ig([&] { report.emplace(loop.value()->run()); });
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(loop.value()->port());
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  auto send = [&](const std::vector<uint8_t>& b) {
    ::sendto(fd, b.data(), b.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
  };
  std::mt19937 rng(5);
  const std::vector<uint8_t> good =
      cigi::writeDatagram(std::vector<cigi::Packet>{cigi::IgControl{}});
  size_t malformed = 0;
  for (int i = 0; i < 50; ++i) {
    std::vector<uint8_t> junk(1 + rng() % 200);
    for (uint8_t& b : junk) b = uint8_t(rng());
    junk[0] = uint8_t(2 + rng() % 200);  // never an IG Control first
    send(junk);
    ++malformed;
    std::vector<uint8_t> truncated(good.begin(),
                                   good.begin() + std::ptrdiff_t(rng() % good.size()));
    send(truncated);
    ++malformed;
    std::vector<uint8_t> version = good;
    version[2] = 2;  // CIGI 2
    send(version);
    ++malformed;
  }
  // Well-formed datagrams with an unknown packet and an entity out of range: not malformed.
  std::vector<uint8_t> unknown = good;
  unknown.insert(unknown.end(), {200, 8, 0, 0, 0, 0, 0, 0});
  send(unknown);
  cigi::EntityControl far;
  far.entity = 65000;
  send(cigi::writeDatagram(std::vector<cigi::Packet>{cigi::IgControl{}, far}));
  ::close(fd);
  ig.join();
  ASSERT_TRUE(report->ok()) << report->error().str();
  EXPECT_EQ(report->value().frames, 40u);
  EXPECT_EQ(report->value().malformed, malformed);
  EXPECT_EQ(report->value().rejected, 1u);
  EXPECT_EQ(report->value().datagrams, 2u);
}

// Config `c` at full quality first, ungoverned, as fast as it goes; then at a rate whose deadline
// is half that frame time — the scene needs twice the budget at full quality — governed.
void expectTheGovernorHoldsTheRate(IgConfig c) {
  IgRunOptions probe;
  probe.frames = 8;
  probe.realtime = false;
  probe.governor = false;
  Result<std::unique_ptr<IgLoop>> first = IgLoop::create(c, probe);
  ASSERT_TRUE(first.ok()) << first.error().str();
  Result<IgRunReport> full = first.value()->run();
  ASSERT_TRUE(full.ok());
  c.rate = 1000 / (full->frameMsP50 / (2 * c.deadline));
  IgRunOptions run;
  run.frames = 120;
  Result<std::unique_ptr<IgLoop>> loop = IgLoop::create(c, run);
  ASSERT_TRUE(loop.ok()) << loop.error().str();
  Result<IgRunReport> r = loop.value()->run();
  ASSERT_TRUE(r.ok());
  const double budget = 1000 / c.rate * c.deadline;
  std::printf("full quality %.2f ms, budget %.2f ms\n%s\n", full->frameMsP50, budget,
              r->summary().c_str());
  EXPECT_GT(r->degraded, 100u) << r->summary();
  // Ungoverned, every frame would take twice the budget. Governed, the 99th percentile stays
  // within it — here with half again to spare for a machine shared with other work (ctest runs
  // tests in parallel, and under the sanitizers); `synthvis ig` over 1 000 frames holds the
  // strict figure (docs/ig.md).
  EXPECT_LE(r->frameMsP99, 1.5 * budget) << r->summary();
  EXPECT_LE(r->missed, 6u) << r->summary();
}

TEST(IgLoop, OverloadProtectionHoldsTheRateOfATooHeavyScene) {
  // 16 samples; the channel 160×120.
  IgConfig c = config();
  c.render.samples = 16;
  expectTheGovernorHoldsTheRate(c);
}

TEST(IgLoop, OverloadProtectionHoldsTheRateOfATerrainOnlyScene) {
  // The terrain is all the frame draws (bicubic hills, 640×360: at 320×180 the bicubic packets
  // made the frame ~7 ms, and the budget derived from it near a shared machine's noise): its
  // cost is the governor's to see, pass by pass (overload.h).
  Result<IgConfig> c = loadIgConfig(std::string(SV_TEST_DATA_DIR) + "/ig/terrain.json");
  ASSERT_TRUE(c.ok()) << c.error().str();
  expectTheGovernorHoldsTheRate(c.value());
}

}  // namespace
}  // namespace sv::ig
