// Several processes as one image generator (issue 36, docs/cluster.md): the ranks of an MPI job
// started by `mpirun -n N synthvis ig CONFIG`. Rank 0 speaks to the host and broadcasts each
// frame's input; every rank draws its channels; the frame lock releases them together. Started
// without mpirun, a process is a cluster of one and never initializes MPI (whose start-up costs
// half a second and a helper process).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "synthvis/result.h"
#include "synthvis/tile_share.h"

namespace sv::cluster {

// True when this process was started by mpirun (Open MPI's or PMIx's environment is set).
bool launchedByMpi();

// What a rank reports when it has drawn a frame: the frame's number and the quality level its own
// overload protection chose (ig/overload.h).
struct FrameDone {
  uint32_t frame = 0;
  int32_t level = 0;
};

class Cluster {
 public:
  // Joins the MPI job when launchedByMpi(), else a cluster of this process alone.
  static Result<std::unique_ptr<Cluster>> join();
  ~Cluster();
  Cluster(const Cluster&) = delete;
  Cluster& operator=(const Cluster&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  // Rank r's name: "rank r on HOST".
  std::string name(int rank) const;

  // Rank 0's `bytes` to every rank (the others' are replaced). A rank that waits longer than
  // `timeoutSeconds` for rank 0 gets an error naming it.
  Status broadcast(std::vector<uint8_t>& bytes, double timeoutSeconds);

  // The largest of every rank's `value`, on every rank (the quality level all ranks draw at when
  // they share channels: a shared channel's parts must draw alike).
  // Waits as frameLock does, naming whoever does not answer.
  Result<int> agreeMax(uint32_t frame, int value, double timeoutSeconds);

  // The parts of one shared channel (synthvis/tile_share.h): `ranks`, in part order, exchanging
  // over their own communicator. Every rank of the job calls it, for the same groups in the same
  // order (the communicator's creation is collective); a rank not in `ranks` gets nullptr. A part
  // that does not answer within `timeoutSeconds` is named in the exchange's error.
  std::unique_ptr<TileExchange> shareGroup(const std::vector<int>& ranks, double timeoutSeconds);

  // The frame lock (a software swap lock): every rank reports `done`; rank 0 waits for all of
  // them at most `timeoutSeconds`, then releases them together with the worst level reported
  // (the result, on every rank). A rank that has not answered in time is named in the error
  // (rank 0's; the others wait twice as long for rank 0, then name it); the caller ends the job
  // (abort) — never a hang.
  Result<int> frameLock(const FrameDone& done, double timeoutSeconds);

  // Ends the whole job at once with `message` on standard error and exit status 3 (MPI_Abort);
  // a cluster of one exits the process.
  [[noreturn]] void abort(const std::string& message);

 private:
  Cluster() = default;
  // frameLock's pattern on its own pair of tags: (frame, value) up to rank 0, the worst back.
  Result<int> worstOf(const FrameDone& done, int tagUp, int tagDown, double timeoutSeconds);
  bool mpi_ = false;
  int rank_ = 0, size_ = 1;
  std::vector<std::string> hosts_;  // by rank
};

}  // namespace sv::cluster
