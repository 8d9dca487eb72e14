// A small fork-join thread pool: the frame's parallel loops (triangle setup chunks, screen tiles).
//
// Work items are handed out dynamically (an atomic counter), so which thread runs an item varies
// from run to run; callers keep results per item, never per thread, which keeps images identical
// for any thread count (SPEC §6).
//
// A frame's parallel loops follow each other closely (vertices, setup, tiles), and waking a thread
// that sleeps on a condition variable costs tens of microseconds on a virtual machine: a worker
// that finishes a loop, and the caller waiting for the workers, spin briefly (kSpin pauses, some
// 50 µs on x86-64; elsewhere the pause is empty and the spin much shorter) before they sleep.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace sv::core {

class ThreadPool {
 public:
  // `threads` ≥ 1 workers in all, the calling thread included.
  explicit ThreadPool(int threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int threadCount() const { return static_cast<int>(workers_.size()) + 1; }

  // Calls fn(item, worker) for every item in [0, count), spread over the workers; returns when all
  // are done. `worker` ∈ [0, threadCount()) identifies the calling worker (for scratch memory).
  // Not reentrant: fn must not call parallelFor.
  void parallelFor(size_t count, const std::function<void(size_t item, int worker)>& fn);

 private:
  void workerLoop(int worker);
  void runItems(int worker);

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable done_;
  const std::function<void(size_t, int)>* job_ = nullptr;
  size_t count_ = 0;
  std::atomic<size_t> next_{0};
  std::atomic<int> busy_{0};             // workers still inside the current job
  std::atomic<unsigned> generation_{0};  // bumped per job so sleeping workers see a new one
  bool stop_ = false;
};

}  // namespace sv::core
