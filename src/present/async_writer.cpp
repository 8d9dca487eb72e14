#include "present/async_writer.h"

namespace sv::present::detail {

AsyncWriter::AsyncWriter(Sink sink, size_t depth)
    : sink_(std::move(sink)), depth_(depth), thread_([this] { run(); }) {}

AsyncWriter::~AsyncWriter() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

Status AsyncWriter::takeError() {
  Status s = error_;
  error_ = Status();
  return s;
}

Status AsyncWriter::submit(const Frame& frame) {
  std::unique_lock lock(mutex_);
  if (queue_.size() >= depth_) {
    dropped_.fetch_add(1, std::memory_order_relaxed);
    return takeError();
  }
  // The copy is made under the lock but costs a memcpy per channel, far less than encoding it.
  queue_.push_back(OwnedFrame{frame.number, {frame.channels.begin(), frame.channels.end()},
                              {frame.names.begin(), frame.names.end()}});
  Status s = takeError();
  lock.unlock();
  wake_.notify_one();
  return s;
}

Status AsyncWriter::flush() {
  std::unique_lock lock(mutex_);
  idle_.wait(lock, [this] { return queue_.empty() && !busy_; });
  return takeError();
}

void AsyncWriter::run() {
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping, and everything written
    OwnedFrame frame = std::move(queue_.front());
    queue_.pop_front();
    busy_ = true;
    lock.unlock();
    Status s = sink_(frame);
    lock.lock();
    busy_ = false;
    if (!s.ok() && error_.ok()) error_ = s;  // the first error is the telling one
    if (queue_.empty()) idle_.notify_all();
  }
}

}  // namespace sv::present::detail
