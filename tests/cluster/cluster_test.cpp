// The image generator over several processes (issue 36, docs/cluster.md). Which rank draws which
// channel, and the errors a bad assignment gets; then `mpirun -n 3 synthvis ig` on this machine:
// the three ranks' channels are bit-identical to the same channels drawn by one process, every
// rank's frame N is at the same simulation time, a bad assignment is refused at start, and a rank
// that stops answering ends the job within the timeout with an error naming it — never a hang.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "support/shell.h"
#include "support/temp_dir.h"
#include "synthvis/ig.h"

namespace sv {
namespace {

namespace fs = std::filesystem;

ig::IgConfig withRanks(std::vector<std::vector<int>> ranks) {
  ig::IgConfig c;
  c.ranks = std::move(ranks);
  return c;
}

// The channels each rank draws, written "c" for a whole channel and "c:p/P" for part p of P.
using Drawn = std::vector<std::vector<std::string>>;
Result<Drawn> drawnBy(const ig::IgConfig& config, int channels, int ranks) {
  Result<std::vector<std::vector<ChannelShare>>> r = ig::channelsByRank(config, channels, ranks);
  if (!r) return r.error();
  Drawn out;
  for (const auto& rank : r.value()) {
    out.emplace_back();
    for (const ChannelShare& c : rank)
      out.back().push_back(c.tiles.shared() ? fmt::format("{}:{}/{}", c.channel, c.tiles.part,
                                                          c.tiles.parts)
                                            : std::to_string(c.channel));
  }
  return out;
}

std::string errorOf(const Result<Drawn>& x) { return x.ok() ? std::string() : x.error().message; }

ig::IgConfig withSplits(std::vector<ig::IgConfig::Split> splits,
                        std::vector<std::vector<int>> ranks = {}) {
  ig::IgConfig c = withRanks(std::move(ranks));
  c.splits = std::move(splits);
  return c;
}

TEST(Cluster, ChannelsGoRoundTheRanksOrAsAssignedAndABadAssignmentIsRefused) {
  auto r = drawnBy(ig::IgConfig{}, 5, 2);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.value(), (Drawn{{"0", "2", "4"}, {"1", "3"}}));
  r = drawnBy(withRanks({{2}, {0, 1}}), 3, 2);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.value(), (Drawn{{"2"}, {"0", "1"}}));
  EXPECT_NE(errorOf(drawnBy(ig::IgConfig{}, 2, 3)).find("3 ranks for 2 channels"),
            std::string::npos);
  EXPECT_NE(errorOf(drawnBy(withRanks({{0}, {1}}), 2, 3)).find("the job has 3"),
            std::string::npos);
  EXPECT_NE(errorOf(drawnBy(withRanks({{0, 1}, {1}}), 2, 2))
                .find("channel 1 is assigned to rank 0 and to rank 1"),
            std::string::npos);
  EXPECT_NE(errorOf(drawnBy(withRanks({{0}, {}}), 2, 2)).find("channel 1 is assigned to no rank"),
            std::string::npos);
  EXPECT_NE(errorOf(drawnBy(withRanks({{0}, {5}}), 2, 2)).find("channel 5 does not exist"),
            std::string::npos);
}

TEST(Cluster, ASplitChannelIsDealtToItsRanksInPartOrderAndABadSplitIsRefused) {
  // Channel 1 over ranks 2, 0 (rank 2 is part 0: it assembles and shows it); the others dealt.
  auto r = drawnBy(withSplits({{1, {2, 0}}}), 4, 3);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.value(), (Drawn{{"0", "1:1/2"}, {"2"}, {"1:0/2", "3"}}));
  // One channel over every rank: nobody idle, though there are more ranks than channels.
  r = drawnBy(withSplits({{0, {0, 1, 2}}}), 1, 3);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.value(), (Drawn{{"0:0/3"}, {"0:1/3"}, {"0:2/3"}}));
  r = drawnBy(withSplits({{0, {1, 0}}}, {{1}, {}}), 2, 2);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.value(), (Drawn{{"0:1/2", "1"}, {"0:0/2"}}));
  EXPECT_NE(errorOf(drawnBy(withSplits({{0, {0, 1}}}, {{0}, {1}}), 2, 2))
                .find("channel 0 is assigned to ranks 0, 1 (split) and to rank 0"),
            std::string::npos);
  EXPECT_NE(errorOf(drawnBy(withSplits({{0, {0, 3}}}), 2, 2)).find("rank 3 does not exist"),
            std::string::npos);
  EXPECT_NE(errorOf(drawnBy(withSplits({{0, {1, 1}}}), 2, 2)).find("rank 1 is listed twice"),
            std::string::npos);
  EXPECT_NE(errorOf(drawnBy(withSplits({{0, {0, 1}}, {0, {1, 0}}}), 2, 2))
                .find("channel 0 is split twice"),
            std::string::npos);
  EXPECT_NE(errorOf(drawnBy(withSplits({{4, {0, 1}}}), 2, 2)).find("channel 4 does not exist"),
            std::string::npos);
  EXPECT_NE(errorOf(drawnBy(withSplits({{0, {0, 1}}}), 2, 4)).find("rank 2 draws nothing"),
            std::string::npos);
}

using tests::ShellRun;

// `command` under `timeout`, so that a hang fails the test instead of stalling it.
ShellRun shell(const std::string& command) { return tests::shell("timeout 120 " + command); }

// mpirun for 3 ranks on this machine: as root if need be, more ranks than cores, no ssh (the
// ranks are local), and Open MPI's own start-up allocations not counted as our leaks.
std::string mpirun(int ranks) {
  return "env OMPI_MCA_plm_rsh_agent=false ASAN_OPTIONS=detect_leaks=0 " + std::string(SV_MPIEXEC) +
         " --allow-run-as-root --oversubscribe -n " + std::to_string(ranks) + " ";
}

fs::path tempDir() { return tests::processTemp().dir(); }

std::string config(const std::string& name, const std::string& extra,
                   const std::string& scene = "mixed.json",
                   const std::string& channels = R"("count": 3, "arc": 120, "width": 96, "height": 72)") {
  const fs::path p = tempDir() / name;
  std::ofstream(p) << R"({"synthvis-ig": 1, "scene": ")" << SV_SOURCE_DIR << "/scenes/" << scene
                   << R"(", "rate": 30, "channels": {)" << channels << R"(},
    "port": 0, "host": {"port": 0})"
                   << extra << "}";
  return p.string();
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(f)), {});
}

TEST(Cluster, ThreeRanksDrawTheChannelsOneProcessDrawsAtTheSameInstants) {
  const std::string cfg = config("three.json", "");
  const fs::path one = tempDir() / "one", three = tempDir() / "three";
  const std::string args = " ig " + cfg + " --frames 4 --as-fast-as-possible --no-governor";
  const ShellRun a = shell(std::string(SV_CLI) + args + " --output png:" + one.string());
  ASSERT_EQ(a.status, 0) << a.out;
  const ShellRun b = shell(mpirun(3) + SV_CLI + args + " --output png:" + three.string() +
                           " --status " + (tempDir() / "status").string());
  ASSERT_EQ(b.status, 0) << b.out;
  EXPECT_NE(b.out.find("3 ranks"), std::string::npos) << b.out;
  int files = 0;
  for (const auto& e : fs::directory_iterator(one)) {
    const fs::path other = three / e.path().filename();
    ASSERT_TRUE(fs::exists(other)) << other;
    EXPECT_EQ(slurp(e.path()), slurp(other)) << e.path().filename();
    ++files;
  }
  EXPECT_EQ(files, 12);  // 4 frames × 3 channels
  // Every rank's status stream: frame N at N / rate seconds, on every rank.
  for (int rank = 0; rank < 3; ++rank) {
    std::ifstream status(tempDir() / ("status.rank" + std::to_string(rank)));
    std::string line;
    int frames = 0;
    while (std::getline(status, line)) {
      const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
      ASSERT_TRUE(j.is_object()) << line;
      EXPECT_EQ(j.value("frame", -1), frames) << line;
      EXPECT_EQ(j.value("rank", -1), rank) << line;
      EXPECT_NEAR(j.value("time", -1.0), frames / 30.0, 1e-6) << line;
      ++frames;
    }
    EXPECT_EQ(frames, 4) << "rank " << rank;
  }
}

// Every file of `one` has its twin in `other`, byte for byte; returns how many.
int expectSameFiles(const fs::path& one, const fs::path& other) {
  int files = 0;
  for (const auto& e : fs::directory_iterator(one)) {
    const fs::path twin = other / e.path().filename();
    EXPECT_TRUE(fs::exists(twin)) << twin;
    EXPECT_EQ(slurp(e.path()), slurp(twin)) << e.path().filename();
    ++files;
  }
  return files;
}

// Issue 61: a curved screen under MPI — a projector per rank, each drawn through its own
// correction and blend — gives the frames one process draws.
TEST(Cluster, ThreeRanksDrawADisplaysProjectorsAsOneProcessDoes) {
  const fs::path cfg = tempDir() / "cylinder.json";
  std::ofstream(cfg) << R"({"synthvis-ig": 1, "scene": ")" << SV_SOURCE_DIR
                     << R"(/scenes/mixed.json", "rate": 30, "port": 0, "host": {"port": 0},
    "display": {"cylinder": {"width": 96, "height": 64}}})";
  const fs::path one = tempDir() / "display-one", three = tempDir() / "display-three";
  const std::string args =
      " ig " + cfg.string() + " --frames 3 --as-fast-as-possible --no-governor";
  const ShellRun a = shell(std::string(SV_CLI) + args + " --output png:" + one.string());
  ASSERT_EQ(a.status, 0) << a.out;
  const ShellRun b = shell(mpirun(3) + SV_CLI + args + " --output png:" + three.string());
  ASSERT_EQ(b.status, 0) << b.out;
  EXPECT_EQ(expectSameFiles(one, three), 9);  // 3 frames × 3 projectors
  EXPECT_TRUE(fs::exists(three / "frame-000002-centre.png"));
}

TEST(Cluster, ASplitChannelIsTheImageOneProcessDraws) {
  // The airport at night (light points, whose visibility reads depth across tile borders; fog),
  // 4 samples a pixel: channel 1 split over ranks 2 and 0 (rank 2 assembles and shows it), the
  // others on ranks 0 and 1.
  const std::string channels = R"("count": 3, "arc": 150, "width": 200, "height": 120)";
  const std::string render = R"(, "render": {"threads": 1, "aa": 4})";
  const std::string whole = config("whole.json", render, "airport.json", channels);
  const std::string split = config(
      "split.json", render + R"(, "cluster": {"split": [{"channel": 1, "ranks": [2, 0]}]})",
      "airport.json", channels);
  const fs::path one = tempDir() / "split-one", three = tempDir() / "split-three";
  const std::string args = " --frames 3 --as-fast-as-possible --no-governor --output png:";
  const ShellRun a = shell(std::string(SV_CLI) + " ig " + whole + args + one.string());
  ASSERT_EQ(a.status, 0) << a.out;
  const ShellRun b = shell(mpirun(3) + SV_CLI + " ig " + split + args + three.string() +
                           " --status " + (tempDir() / "split-status").string());
  ASSERT_EQ(b.status, 0) << b.out;
  EXPECT_EQ(expectSameFiles(one, three), 9);  // 3 frames × 3 channels
  EXPECT_EQ(expectSameFiles(three, one), 9);  // and no file besides
  // The parts' status lines say what crossed between them.
  for (int rank : {0, 2}) {
    std::ifstream status(tempDir() / ("split-status.rank" + std::to_string(rank)));
    std::string line;
    ASSERT_TRUE(std::getline(status, line));
    EXPECT_NE(line.find("\"shareBytes\":"), std::string::npos) << line;
    EXPECT_EQ(line.find("\"shareBytes\":0,"), std::string::npos) << line;
  }
}

TEST(Cluster, RankZeroIsTheIgAHostDrivesAndWiresharkReadsItsSession) {
  // The IG issue's conformance check with three ranks (one channel split over two): the host
  // drives rank 0 over loopback UDP; the recorded session is read by Wireshark's CIGI dissector
  // with no malformed packet, one Start of Frame per frame counting 0, 1, 2, …, the host's
  // entity in it — and the host heard one IG, not three.
  const int igPort = 20000 + int(::getpid() % 20000);
  constexpr int kFrames = 150;  // 5 s at 30 Hz: the host's 40 frames fit after the job's start
  const std::string cfg = config(
      "cigi.json",
      fmt::format(R"(, "render": {{"threads": 1}}, "cluster": {{"split": [{{"channel": 1, "ranks": [1, 2]}}]}})"),
      "airport.json", R"("count": 3, "arc": 150, "width": 160, "height": 96)");
  {  // the IG listens on igPort and answers whoever drives it
    std::ifstream in(cfg);
    std::string text((std::istreambuf_iterator<char>(in)), {});
    text.replace(text.find(R"("port": 0, "host": {"port": 0})"), 30,
                 fmt::format(R"("port": {}, "host": {{"port": 0}})", igPort));
    std::ofstream(cfg) << text;
  }
  const fs::path script = tempDir() / "host.json";
  std::ofstream(script) << fmt::format(R"({{"synthvis-host": 1, "origin": {{"lat": 0, "lon": 0, "alt": 0}},
    "ig": {{"address": "127.0.0.1", "port": {}}}, "port": 0, "rate": 30, "frames": 40,
    "entities": [{{"id": 0, "type": 0, "path": [{{"t": 0, "north": -900, "up": 60, "pitch": -3}},
                                                {{"t": 2, "north": -800, "up": 55, "pitch": -3}}]}}],
    "events": [{{"t": 0.3, "hat": {{"id": 5, "north": -850, "up": 100}}}}]}})",
                                       igPort);
  const fs::path capture = tempDir() / "cluster-session.pcap";
  const fs::path status = tempDir() / "cigi-status";
  // The host starts once rank 0 has drawn its first frame (its status line): the job's start-up
  // takes seconds on a loaded machine, longer than the host waits for a first Start of Frame.
  const ShellRun r = shell(
      "sh -c '" + mpirun(3) + SV_CLI + " ig " + cfg + " --frames " + std::to_string(kFrames) +
      " --no-governor --output null --record " + capture.string() + " --status " +
      status.string() + " & for i in $(seq 1 400); do [ -s " + status.string() +
      ".rank0 ] && break; sleep 0.05; done; " + SV_CLI + " host " + script.string() + "; wait'");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("host: 40 frames sent"), std::string::npos) << r.out;
  // One Start of Frame a frame: the host sends a frame for each it hears, so it heard about 40 —
  // not three times as many from three ranks.
  unsigned sent = 0, heard = 0;
  const size_t at = r.out.find("host: ");
  ASSERT_NE(at, std::string::npos) << r.out;
  ASSERT_EQ(std::sscanf(r.out.c_str() + at, "host: %u frames sent, %u Start of Frame", &sent, &heard),
            2)
      << r.out;
  EXPECT_GE(heard, 40u);
  EXPECT_LE(heard, 42u);
  // tshark's output alone (its warnings to standard error dropped).
  const auto tshark = [&](const std::string& args) {
    return tests::shell("(tshark -n -r '" + capture.string() +
                        "' -d udp.port==8004,cigi -d udp.port==8005,cigi " + args + " 2>/dev/null)")
        .out;
  };
  EXPECT_EQ(tshark("-Y '_ws.malformed || _ws.expert.severity >= error'"), "");
  std::string counting;
  for (int f = 0; f < kFrames; ++f) counting += std::to_string(f) + "\n";
  EXPECT_EQ(tshark("-Y cigi.sof -T fields -e cigi.sof.ig_frame_number"), counting);
  EXPECT_NE(tshark("-Y 'cigi.entity_control.entity_id == 0' -T fields -e frame.number"), "");
  EXPECT_NE(tshark("-Y cigi.hat_hot_response -T fields -e cigi.hat_hot_response.hat_hot_id"), "");
}

TEST(Cluster, ARankThatShowsNothingOpensNoOutput) {
  // One channel split over both ranks: rank 1 draws half of it and shows nothing, so only rank 0
  // writes the y4m stream (a stream of no channels has no frame to write).
  const std::string cfg = config("nothing.json", R"(, "cluster": {"split": [{"channel": 0, "ranks": [0, 1]}]})",
                                 "mixed.json", R"("count": 1, "arc": 60, "width": 96, "height": 64)");
  const fs::path y4m = tempDir() / "nothing.y4m";
  const ShellRun r = shell(mpirun(2) + SV_CLI + " ig " + cfg +
                           " --frames 3 --as-fast-as-possible --no-governor --output y4m:" +
                           y4m.string());
  ASSERT_EQ(r.status, 0) << r.out;
  const std::string stream = slurp(y4m);
  size_t frames = 0;
  for (size_t at = stream.find("FRAME\n"); at != std::string::npos;
       at = stream.find("FRAME\n", at + 1))
    ++frames;
  EXPECT_EQ(frames, 3u);
  EXPECT_EQ(stream.rfind("YUV4MPEG2 W96 H64", 0), 0u) << stream.substr(0, 40);
}

TEST(Cluster, RanksShowingChannelsWriteAY4mStreamEachAndRefuseOnePipe) {
  // Two ranks, a channel each: on one machine a shared path would be written by both at once, so
  // each rank writes PATH.rankR, a whole stream of its own channel.
  const std::string cfg = config("two.json", "", "mixed.json",
                                 R"("count": 2, "arc": 90, "width": 96, "height": 64)");
  const fs::path y4m = tempDir() / "two.y4m";
  const std::string args = " ig " + cfg + " --frames 3 --as-fast-as-possible --no-governor";
  const ShellRun r = shell(mpirun(2) + SV_CLI + args + " --output y4m:" + y4m.string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_FALSE(fs::exists(y4m));
  for (int rank = 0; rank < 2; ++rank) {
    const std::string stream = slurp(y4m.string() + ".rank" + std::to_string(rank));
    EXPECT_EQ(stream.rfind("YUV4MPEG2 W96 H64", 0), 0u) << rank << ": " << stream.substr(0, 40);
    EXPECT_EQ(stream.size(), stream.find('\n') + 1 + 3 * (6 + 3 * 96 * 64)) << rank;
  }
  const ShellRun pipe = shell(mpirun(2) + SV_CLI + args + " --output y4m:-");
  EXPECT_NE(pipe.status, 0);
  EXPECT_NE(pipe.out.find("2 ranks show channels and their streams would interleave"),
            std::string::npos)
      << pipe.out;
}

TEST(Cluster, ABadAssignmentIsRefusedAtStart) {
  const std::string cfg = config("bad.json", R"(, "cluster": {"ranks": [[0, 1], [1, 2], []]})");
  const ShellRun r = shell(mpirun(3) + SV_CLI + " ig " + cfg + " --frames 2 --as-fast-as-possible");
  EXPECT_NE(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("channel 1 is assigned to rank 0 and to rank 1"), std::string::npos) << r.out;
}

// Runs `config` on 3 ranks and sends rank `stopped` `signal` (STOP: it stops answering; KILL: it
// dies) once the run is under way; the job's output, and the seconds it took to end.
std::pair<ShellRun, double> runAndStop(const std::string& cfg, int stopped,
                                       const std::string& signal = "STOP") {
  const fs::path status = tempDir() / ("stop-status" + std::to_string(stopped));
  // The driver, as a script: the stopper in the background, then the job.
  const fs::path script = tempDir() / "stop.sh";
  std::ofstream(script) << "for i in $(seq 1 400); do [ -s " << status.string() << ".rank"
                        << stopped << " ] && break; sleep 0.05; done\n"
                        << "for p in $(pgrep -f 'ig " << cfg << "'); do\n"
                        << "  if tr '\\0' '\\n' < /proc/$p/environ 2>/dev/null | "
                        << "grep -qx OMPI_COMM_WORLD_RANK=" << stopped
                        << "; then kill -" << signal << " $p; fi\n"
                        << "done\n";
  const auto start = std::chrono::steady_clock::now();
  const ShellRun r =
      shell("sh -c 'sh " + script.string() + " & " + mpirun(3) + SV_CLI + " ig " + cfg +
            " --frames 100000 --no-governor --status " + status.string() + "'");
  return {r, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()};
}

TEST(Cluster, ARankThatStopsAnsweringEndsTheJobNamedWithinTheTimeout) {
  // Rank 2 stopped: rank 0's frame lock waits 1 s for it, then ends the job naming it.
  const auto [r, seconds] = runAndStop(config("stop.json", R"(, "cluster": {"timeout": 1})"), 2);
  EXPECT_NE(r.status, 0) << r.out;
  EXPECT_NE(r.status, 124) << "timed out: " << r.out;
  EXPECT_NE(r.out.find("no answer within 1 s from rank 2 on "), std::string::npos) << r.out;
  EXPECT_LT(seconds, 60) << r.out;
}

TEST(Cluster, ARankKilledMidRunEndsTheJobNamed) {
  // mpirun sees the death and ends the job at once, naming the rank.
  const auto [r, seconds] = runAndStop(config("kill.json", R"(, "cluster": {"timeout": 1})"), 1, "KILL");
  EXPECT_NE(r.status, 0) << r.out;
  EXPECT_NE(r.status, 124) << "timed out: " << r.out;
  EXPECT_NE(r.out.find("rank 1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("signal 9"), std::string::npos) << r.out;
  EXPECT_LT(seconds, 60) << r.out;
}

TEST(Cluster, ARankZeroThatStopsAnsweringIsNamedByTheOthers) {
  // Rank 0 stopped, with a channel split over all three ranks: the others wait twice the
  // timeout for it (at the broadcast, the quality level, the gather or the frame lock), then
  // end the job naming it.
  const auto [r, seconds] = runAndStop(
      config("stop0.json",
             R"(, "cluster": {"timeout": 1, "split": [{"channel": 0, "ranks": [0, 1, 2]}]})"),
      0);
  EXPECT_NE(r.status, 0) << r.out;
  EXPECT_NE(r.status, 124) << "timed out: " << r.out;
  EXPECT_NE(r.out.find("no answer within 2 s from rank 0 on "), std::string::npos) << r.out;
  EXPECT_LT(seconds, 60) << r.out;
}

}  // namespace
}  // namespace sv
