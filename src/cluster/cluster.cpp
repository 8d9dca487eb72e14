// Based on: SPEC §9 (all channels of a frame show the same simulation instant), §3.4 (one picture
// over several processors); the MPI standard's broadcast, point-to-point messages and MPI_Abort.
#include "synthvis/cluster.h"

#include <fmt/format.h>
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <thread>

namespace sv::cluster {
namespace {

constexpr int kTagDone = 1, kTagGo = 2, kTagTiles = 3, kTagValues = 4, kTagMax = 5,
              kTagLevel = 6, kTagAgreed = 7;
using SteadyClock = std::chrono::steady_clock;
constexpr int kSpinMicroseconds = 300;

SteadyClock::time_point after(double seconds) {
  return SteadyClock::now() +
         std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(seconds));
}

// Polls `requests` until every one is complete, or fails at `deadline` naming those that are
// not (who(i) names request i's peer). Polling, not MPI_Waitall: MPI itself never times out, and
// a hung peer must end the job, not stall it.
Status waitAll(std::vector<MPI_Request>& requests, SteadyClock::time_point deadline,
               double seconds, const std::function<std::string(size_t)>& who) {
  // Each test drives MPI's progress, so the first 0.3 ms — a message on its way — are polled back
  // to back; a longer wait (a peer still drawing) sleeps 50 µs between tests, so that a waiting
  // rank does not take a core from one still drawing when there are more ranks than cores.
  const auto spinUntil = SteadyClock::now() + std::chrono::microseconds(kSpinMicroseconds);
  for (;;) {
    int done = 0;
    MPI_Testall(int(requests.size()), requests.data(), &done, MPI_STATUSES_IGNORE);
    if (done) return {};
    const auto now = SteadyClock::now();
    if (now > deadline) break;
    if (now > spinUntil) std::this_thread::sleep_for(std::chrono::microseconds(50));
  }
  std::string missing;
  for (size_t i = 0; i < requests.size(); ++i) {
    int flag = 0;
    if (requests[i] != MPI_REQUEST_NULL) MPI_Test(&requests[i], &flag, MPI_STATUS_IGNORE);
    if (requests[i] != MPI_REQUEST_NULL && !flag) {
      const std::string name = who(i);
      if (missing.find(name) == std::string::npos)
        missing += (missing.empty() ? "" : ", ") + name;
    }
  }
  return Error{"", "", fmt::format("no answer within {:g} s from {}", seconds, missing)};
}

Status tooLarge(size_t bytes) {
  return Error{"", "", fmt::format("a message of {} bytes is beyond MPI's int counts", bytes)};
}

// The parts of one shared channel over their own communicator (part p = its rank p).
class MpiExchange final : public TileExchange {
 public:
  MpiExchange(MPI_Comm comm, std::vector<int> ranks, int part, double timeout,
              const Cluster& cluster)
      : comm_(comm), ranks_(std::move(ranks)), part_(part), timeout_(timeout), cluster_(cluster) {}
  ~MpiExchange() override { MPI_Comm_free(&comm_); }

  Status gather(const std::vector<uint8_t>& mine,
                std::vector<std::vector<uint8_t>>& all) override {
    if (mine.size() > size_t(INT32_MAX)) return tooLarge(mine.size());
    std::vector<MPI_Request> requests;
    if (part_ != 0) {
      requests.assign(1, MPI_REQUEST_NULL);
      MPI_Isend(mine.data(), int(mine.size()), MPI_BYTE, 0, kTagTiles, comm_, &requests[0]);
      return waitAll(requests, after(2 * timeout_), 2 * timeout_, [&](size_t) { return name(0); });
    }
    requests.assign(all.size() - 1, MPI_REQUEST_NULL);
    for (size_t p = 1; p < all.size(); ++p) {
      if (all[p].size() > size_t(INT32_MAX)) return tooLarge(all[p].size());
      MPI_Irecv(all[p].data(), int(all[p].size()), MPI_BYTE, int(p), kTagTiles, comm_,
                &requests[p - 1]);
    }
    return waitAll(requests, after(timeout_), timeout_, [&](size_t i) { return name(int(i) + 1); });
  }

  Status maxAll(std::vector<float>& values) override {
    if (values.size() > size_t(INT32_MAX)) return tooLarge(values.size() * sizeof(float));
    const int n = int(values.size());
    std::vector<MPI_Request> requests;
    if (part_ != 0) {
      requests.assign(2, MPI_REQUEST_NULL);
      MPI_Isend(values.data(), n, MPI_FLOAT, 0, kTagValues, comm_, &requests[0]);
      std::vector<float> result(values.size());
      MPI_Irecv(result.data(), n, MPI_FLOAT, 0, kTagMax, comm_, &requests[1]);
      if (Status s =
              waitAll(requests, after(2 * timeout_), 2 * timeout_, [&](size_t) { return name(0); });
          !s)
        return s;
      values = std::move(result);
      return {};
    }
    const size_t parts = ranks_.size();
    std::vector<std::vector<float>> theirs(parts, std::vector<float>(values.size()));
    requests.assign(parts - 1, MPI_REQUEST_NULL);
    for (size_t p = 1; p < parts; ++p)
      MPI_Irecv(theirs[p].data(), n, MPI_FLOAT, int(p), kTagValues, comm_, &requests[p - 1]);
    const auto who = [&](size_t i) { return name(int(i) + 1); };
    if (Status s = waitAll(requests, after(timeout_), timeout_, who); !s) return s;
    for (size_t p = 1; p < parts; ++p)
      for (size_t i = 0; i < values.size(); ++i) values[i] = std::max(values[i], theirs[p][i]);
    for (size_t p = 1; p < parts; ++p)
      MPI_Isend(values.data(), n, MPI_FLOAT, int(p), kTagMax, comm_, &requests[p - 1]);
    return waitAll(requests, after(timeout_), timeout_, who);
  }

 private:
  std::string name(int part) const { return cluster_.name(ranks_[size_t(part)]); }

  MPI_Comm comm_;
  std::vector<int> ranks_;  // world ranks, by part
  int part_;
  double timeout_;
  const Cluster& cluster_;
};

}  // namespace

bool launchedByMpi() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMIX_RANK") != nullptr;
}

Result<std::unique_ptr<Cluster>> Cluster::join() {
  std::unique_ptr<Cluster> c(new Cluster());
  if (!launchedByMpi()) {
    c->hosts_ = {"this machine"};
    return c;
  }
  int provided = 0;
  if (MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS)
    return Error{"", "", "MPI: could not join the job (MPI_Init_thread failed)"};
  c->mpi_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &c->rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &c->size_);
  // Every rank's host name, for messages that name a rank.
  char host[MPI_MAX_PROCESSOR_NAME] = {};
  int length = 0;
  MPI_Get_processor_name(host, &length);
  std::vector<char> all(size_t(c->size_) * MPI_MAX_PROCESSOR_NAME);
  MPI_Allgather(host, MPI_MAX_PROCESSOR_NAME, MPI_CHAR, all.data(), MPI_MAX_PROCESSOR_NAME,
                MPI_CHAR, MPI_COMM_WORLD);
  for (int r = 0; r < c->size_; ++r) {
    const char* h = &all[size_t(r) * MPI_MAX_PROCESSOR_NAME];
    c->hosts_.emplace_back(h, strnlen(h, MPI_MAX_PROCESSOR_NAME));
  }
  return c;
}

Cluster::~Cluster() {
  if (mpi_) MPI_Finalize();
}

std::string Cluster::name(int rank) const {
  return fmt::format("rank {} on {}", rank,
                     rank >= 0 && rank < int(hosts_.size()) ? hosts_[size_t(rank)] : "?");
}

Status Cluster::broadcast(std::vector<uint8_t>& bytes, double timeoutSeconds) {
  if (size_ == 1) return {};
  // Polled, as every wait of the job: a rank 0 that hangs is named, not waited for forever.
  const double wait = rank_ == 0 ? timeoutSeconds : 2 * timeoutSeconds;
  const auto deadline = after(wait);
  const auto who = [&](size_t) {
    return rank_ == 0 ? std::string("some rank (the frame's input was not taken)") : name(0);
  };
  uint64_t n = bytes.size();
  std::vector<MPI_Request> request(1, MPI_REQUEST_NULL);
  MPI_Ibcast(&n, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD, &request[0]);
  if (Status s = waitAll(request, deadline, wait, who); !s) return s;
  bytes.resize(size_t(n));
  // In pieces below 2^31 bytes (MPI counts are int).
  for (uint64_t at = 0; at < n;) {
    const int piece = int(std::min<uint64_t>(n - at, 1u << 30));
    MPI_Ibcast(bytes.data() + at, piece, MPI_BYTE, 0, MPI_COMM_WORLD, &request[0]);
    if (Status s = waitAll(request, deadline, wait, who); !s) return s;
    at += uint64_t(piece);
  }
  return {};
}

Result<int> Cluster::agreeMax(uint32_t frame, int value, double timeoutSeconds) {
  return worstOf({frame, value}, kTagLevel, kTagAgreed, timeoutSeconds);
}

std::unique_ptr<TileExchange> Cluster::shareGroup(const std::vector<int>& ranks,
                                                  double timeoutSeconds) {
  const auto at = std::find(ranks.begin(), ranks.end(), rank_);
  if (!mpi_) return nullptr;
  MPI_Comm comm = MPI_COMM_NULL;
  MPI_Comm_split(MPI_COMM_WORLD, at == ranks.end() ? MPI_UNDEFINED : 0,
                 at == ranks.end() ? 0 : int(at - ranks.begin()), &comm);
  if (at == ranks.end()) return nullptr;
  return std::make_unique<MpiExchange>(comm, ranks, int(at - ranks.begin()), timeoutSeconds,
                                       *this);
}

Result<int> Cluster::frameLock(const FrameDone& done, double timeoutSeconds) {
  return worstOf(done, kTagDone, kTagGo, timeoutSeconds);
}

// Every rank's (frame, value) to rank 0, the largest value back — point to point, each wait
// polled, so that whoever does not answer is named: rank 0 names the ranks missing, the others
// rank 0 (given twice the time, as rank 0 may itself be waiting for a slow rank).
Result<int> Cluster::worstOf(const FrameDone& done, int tagUp, int tagDown,
                             double timeoutSeconds) {
  if (size_ == 1) return done.level;
  int32_t worst = done.level;
  if (rank_ != 0) {
    const int32_t message[2] = {int32_t(done.frame), done.level};
    std::vector<MPI_Request> requests(2, MPI_REQUEST_NULL);
    MPI_Isend(message, 2, MPI_INT32_T, 0, tagUp, MPI_COMM_WORLD, &requests[0]);
    MPI_Irecv(&worst, 1, MPI_INT32_T, 0, tagDown, MPI_COMM_WORLD, &requests[1]);
    if (Status s = waitAll(requests, after(2 * timeoutSeconds), 2 * timeoutSeconds,
                           [&](size_t) { return name(0); });
        !s)
      return Error{"", "", fmt::format("frame {}: {}", done.frame, s.error().message)};
    return int(worst);
  }
  std::vector<int32_t> messages(size_t(size_) * 2);
  std::vector<MPI_Request> requests(size_t(size_ - 1), MPI_REQUEST_NULL);
  for (int r = 1; r < size_; ++r)
    MPI_Irecv(&messages[size_t(r) * 2], 2, MPI_INT32_T, r, tagUp, MPI_COMM_WORLD,
              &requests[size_t(r - 1)]);
  if (Status s = waitAll(requests, after(timeoutSeconds), timeoutSeconds,
                         [&](size_t i) { return name(int(i) + 1); });
      !s)
    return Error{"", "", fmt::format("frame {}: {}", done.frame, s.error().message)};
  for (int r = 1; r < size_; ++r) {
    if (uint32_t(messages[size_t(r) * 2]) != done.frame)
      return Error{"", "",
                   fmt::format("frame {}: {} is at frame {} instead", done.frame, name(r),
                               messages[size_t(r) * 2])};
    worst = std::max(worst, messages[size_t(r) * 2 + 1]);
  }
  // Small messages: sent at once, whether or not their rank is still listening.
  for (int r = 1; r < size_; ++r) MPI_Send(&worst, 1, MPI_INT32_T, r, tagDown, MPI_COMM_WORLD);
  return int(worst);
}

void Cluster::abort(const std::string& message) {
  std::fprintf(stderr, "synthvis: %s\n", message.c_str());
  std::fflush(stderr);
  if (mpi_) MPI_Abort(MPI_COMM_WORLD, 3);
  std::exit(3);
}

}  // namespace sv::cluster
