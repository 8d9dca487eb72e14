// The file outputs' writer thread: present() copies the frame into a short queue and returns; the
// thread encodes and writes. A full queue drops the new frame rather than hold up the frame loop.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "present/present.h"

namespace sv::present::detail {

// A Frame whose images and names the queue owns.
struct OwnedFrame {
  uint64_t number = 0;
  std::vector<Image> channels;
  std::vector<std::string> names;
};

class AsyncWriter {
 public:
  // `sink` runs on the writer thread, one frame at a time, in presentation order.
  using Sink = std::function<Status(const OwnedFrame&)>;
  AsyncWriter(Sink sink, size_t depth);
  ~AsyncWriter();  // writes what is queued, then joins
  AsyncWriter(const AsyncWriter&) = delete;
  AsyncWriter& operator=(const AsyncWriter&) = delete;

  // Queues a copy of the frame (or drops it when `depth` frames are waiting); returns the first
  // error the sink reported since the last call, if any.
  Status submit(const Frame& frame);
  Status flush();
  uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }

 private:
  void run();
  Status takeError();  // with mutex_ held

  Sink sink_;
  size_t depth_;
  std::mutex mutex_;
  std::condition_variable wake_;  // work queued, or stopping
  std::condition_variable idle_;  // the queue emptied and nothing is being written
  std::deque<OwnedFrame> queue_;
  bool busy_ = false, stopping_ = false;
  Status error_;
  std::atomic<uint64_t> dropped_{0};
  std::thread thread_;
};

}  // namespace sv::present::detail
