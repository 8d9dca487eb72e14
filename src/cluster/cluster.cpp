// Based on: SPEC §9 (all channels of a frame show the same simulation instant), §3.4 (one picture
// over several processors); the MPI standard's broadcast, point-to-point messages and MPI_Abort.
#include "cluster/cluster.h"

#include <fmt/format.h>
#include <mpi.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>

namespace sv::cluster {
namespace {

constexpr int kTagDone = 1, kTagGo = 2;

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

void Cluster::broadcast(std::vector<uint8_t>& bytes) {
  if (size_ == 1) return;
  uint64_t n = bytes.size();
  MPI_Bcast(&n, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
  bytes.resize(size_t(n));
  // In pieces below 2^31 bytes (MPI counts are int).
  for (uint64_t at = 0; at < n;) {
    const int piece = int(std::min<uint64_t>(n - at, 1u << 30));
    MPI_Bcast(bytes.data() + at, piece, MPI_BYTE, 0, MPI_COMM_WORLD);
    at += uint64_t(piece);
  }
}

Result<int> Cluster::frameLock(const FrameDone& done, double timeoutSeconds) {
  if (size_ == 1) return done.level;
  int32_t worst = done.level;
  if (rank_ != 0) {
    const int32_t message[2] = {int32_t(done.frame), done.level};
    MPI_Send(message, 2, MPI_INT32_T, 0, kTagDone, MPI_COMM_WORLD);
    MPI_Recv(&worst, 1, MPI_INT32_T, 0, kTagGo, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    return int(worst);
  }
  // Rank 0: one receive a rank, polled until all have come or the time is up.
  std::vector<int32_t> messages(size_t(size_) * 2);
  std::vector<MPI_Request> requests(size_t(size_), MPI_REQUEST_NULL);
  for (int r = 1; r < size_; ++r)
    MPI_Irecv(&messages[size_t(r) * 2], 2, MPI_INT32_T, r, kTagDone, MPI_COMM_WORLD,
              &requests[size_t(r)]);
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(timeoutSeconds);
  std::vector<bool> answered(size_t(size_), false);
  answered[0] = true;
  for (;;) {
    bool all = true;
    for (int r = 1; r < size_; ++r) {
      if (answered[size_t(r)]) continue;
      int flag = 0;
      MPI_Test(&requests[size_t(r)], &flag, MPI_STATUS_IGNORE);
      answered[size_t(r)] = flag != 0;
      all = all && flag != 0;
    }
    if (all) break;
    if (std::chrono::steady_clock::now() > deadline) {
      std::string missing;
      for (int r = 1; r < size_; ++r)
        if (!answered[size_t(r)]) missing += (missing.empty() ? "" : ", ") + name(r);
      return Error{"", "",
                   fmt::format("frame {}: no answer within {:g} s from {}", done.frame,
                               timeoutSeconds, missing)};
    }
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
  for (int r = 1; r < size_; ++r) {
    if (uint32_t(messages[size_t(r) * 2]) != done.frame)
      return Error{"", "",
                   fmt::format("frame {}: {} finished frame {} instead", done.frame, name(r),
                               messages[size_t(r) * 2])};
    worst = std::max(worst, messages[size_t(r) * 2 + 1]);
  }
  for (int r = 1; r < size_; ++r) MPI_Send(&worst, 1, MPI_INT32_T, r, kTagGo, MPI_COMM_WORLD);
  return int(worst);
}

void Cluster::abort(const std::string& message) {
  std::fprintf(stderr, "synthvis: %s\n", message.c_str());
  std::fflush(stderr);
  if (mpi_) MPI_Abort(MPI_COMM_WORLD, 3);
  std::exit(3);
}

}  // namespace sv::cluster
