// Based on: SPEC §10 (seed 002: the FIFO of segment words between the geometry and the sorter, and
// the overload protection that sends a line-repeat flag when fewer than a critical number of
// lines are buffered).
#include "segments/channel_clock.h"

#include <algorithm>

#include "core/check.h"

namespace sv::segments {

ChannelClock::ChannelClock(const ChannelTiming& timing, int lines)
    : timing_(timing), lines_(lines) {
  SV_CHECK(timing.wordsPerLine >= 0 && timing.criticalLines >= 1 && timing.fifoWords >= 1);
  SV_CHECK(lines >= 0);
}

int64_t ChannelClock::readBy(int64_t t) const {
  // readAt(k) ≤ t ⟺ k ≤ t / wordsPerLine − criticalLines.
  const int64_t k = t / timing_.wordsPerLine - timing_.criticalLines;
  return std::clamp<int64_t>(k + 1, 0, lines_);
}

void ChannelClock::queue(int j, int64_t words) {
  fifo_.push_back({j, words});
  fifoWords_ += words;
}

bool ChannelClock::startLine(int j) {
  if (timing_.wordsPerLine == 0) return true;
  // The display has started (read line 0) and the lines queued ahead of it are too few.
  const int64_t read = readBy(t_);
  if (read > 0 && j - read < timing_.criticalLines) {
    t_ += 1;  // the repeat flag
    queue(j, 1);
    return false;
  }
  return true;
}

bool ChannelClock::finishLine(int j, int64_t words) {
  if (timing_.wordsPerLine == 0) return true;
  t_ += words;
  // The display reads the queued lines at their times, freeing their words; the line's last word
  // enters once the FIFO has room for all of it (a line larger than the FIFO never does).
  const auto drop = [&](int64_t t) {
    while (!fifo_.empty() && readAt(fifo_.front().line) <= t) {
      fifoWords_ -= fifo_.front().words;
      fifo_.pop_front();
    }
  };
  drop(t_);
  bool onTime = words <= timing_.fifoWords;
  while (onTime && fifoWords_ + words > timing_.fifoWords) {
    t_ = std::max(t_, readAt(fifo_.front().line));
    drop(t_);
  }
  if (onTime) onTime = t_ < readAt(j);
  if (onTime) {
    queue(j, words);
  } else {
    t_ += 1;  // the repeat flag instead
    queue(j, 1);
  }
  return onTime;
}

}  // namespace sv::segments
