// The image generator over several processes (issue 36, docs/cluster.md). Which rank draws which
// channel, and the errors a bad assignment gets; then `mpirun -n 3 synthvis ig` on this machine:
// the three ranks' channels are bit-identical to the same channels drawn by one process, every
// rank's frame N is at the same simulation time, a bad assignment is refused at start, and a rank
// that stops answering ends the job within the timeout with an error naming it — never a hang.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "ig/config.h"
#include "support/shell.h"
#include "support/temp_dir.h"

namespace sv {
namespace {

namespace fs = std::filesystem;

ig::IgConfig withRanks(std::vector<std::vector<int>> ranks) {
  ig::IgConfig c;
  c.ranks = std::move(ranks);
  return c;
}

TEST(Cluster, ChannelsGoRoundTheRanksOrAsAssignedAndABadAssignmentIsRefused) {
  auto r = ig::channelsByRank(ig::IgConfig{}, 5, 2);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.value(), (std::vector<std::vector<int>>{{0, 2, 4}, {1, 3}}));
  r = ig::channelsByRank(withRanks({{2}, {0, 1}}), 3, 2);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.value(), (std::vector<std::vector<int>>{{2}, {0, 1}}));
  const auto error = [](const Result<std::vector<std::vector<int>>>& x) {
    return x.ok() ? std::string() : x.error().message;
  };
  EXPECT_NE(error(ig::channelsByRank(ig::IgConfig{}, 2, 3)).find("3 ranks for 2 channels"),
            std::string::npos);
  EXPECT_NE(error(ig::channelsByRank(withRanks({{0}, {1}}), 2, 3)).find("the job has 3"),
            std::string::npos);
  EXPECT_NE(error(ig::channelsByRank(withRanks({{0, 1}, {1}}), 2, 2))
                .find("channel 1 is assigned to rank 0 and rank 1"),
            std::string::npos);
  EXPECT_NE(error(ig::channelsByRank(withRanks({{0}, {}}), 2, 2))
                .find("channel 1 is assigned to no rank"),
            std::string::npos);
  EXPECT_NE(error(ig::channelsByRank(withRanks({{0}, {5}}), 2, 2)).find("channel 5 does not exist"),
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

std::string config(const std::string& name, const std::string& extra) {
  const fs::path p = tempDir() / name;
  std::ofstream(p) << R"({"synthvis-ig": 1, "scene": ")" << SV_SOURCE_DIR
                   << R"(/scenes/mixed.json", "rate": 30,
    "channels": {"count": 3, "arc": 120, "width": 96, "height": 72},
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
      const std::string frame = "\"frame\":" + std::to_string(frames) + ",";
      EXPECT_NE(line.find(frame), std::string::npos) << line;
      EXPECT_NE(line.find("\"rank\":" + std::to_string(rank)), std::string::npos) << line;
      char time[64];
      std::snprintf(time, sizeof time, "\"time\":%.6f,", frames / 30.0);
      EXPECT_NE(line.find(time), std::string::npos) << line;
      ++frames;
    }
    EXPECT_EQ(frames, 4) << "rank " << rank;
  }
}

TEST(Cluster, ABadAssignmentIsRefusedAtStart) {
  const std::string cfg = config("bad.json", R"(, "cluster": {"ranks": [[0, 1], [1, 2], []]})");
  const ShellRun r = shell(mpirun(3) + SV_CLI + " ig " + cfg + " --frames 2 --as-fast-as-possible");
  EXPECT_NE(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("channel 1 is assigned to rank 0 and rank 1"), std::string::npos) << r.out;
}

TEST(Cluster, ARankThatStopsAnsweringEndsTheJobNamedWithinTheTimeout) {
  // Rank 2 stopped (SIGSTOP) once the run is under way: rank 0's frame lock waits 1 s for it,
  // then ends the job with an error naming it.
  const std::string cfg = config("stop.json", R"(, "cluster": {"timeout": 1})");
  const fs::path status = tempDir() / "stop-status";
  // The driver, as a script: the stopper in the background, then the job.
  const fs::path script = tempDir() / "stop.sh";
  std::ofstream(script) << "for i in $(seq 1 400); do [ -s " << status.string()
                        << ".rank2 ] && break; sleep 0.05; done\n"
                        << "for p in $(pgrep -f 'ig " << cfg << "'); do\n"
                        << "  if tr '\\0' '\\n' < /proc/$p/environ 2>/dev/null | "
                        << "grep -qx OMPI_COMM_WORLD_RANK=2; then kill -STOP $p; fi\n"
                        << "done\n";
  const auto start = std::chrono::steady_clock::now();
  const ShellRun r =
      shell("sh -c 'sh " + script.string() + " & " + mpirun(3) + SV_CLI + " ig " + cfg +
            " --frames 100000 --no-governor --status " + status.string() + "'");
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_NE(r.status, 0) << r.out;
  EXPECT_NE(r.status, 124) << "timed out: " << r.out;
  EXPECT_NE(r.out.find("no answer within 1 s from rank 2 on "), std::string::npos) << r.out;
  EXPECT_LT(seconds, 60) << r.out;
}

}  // namespace
}  // namespace sv
