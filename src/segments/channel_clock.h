// The video channel's timing and its overload protection (SPEC §10, seed 002), as a model clock:
// a geometry stage that sends a line's segment words into a FIFO at a fixed rate, and a display
// that reads one line per line period whatever happens. When, before a line, fewer than a
// critical number of lines are buffered, the geometry stage sends a line-repeat flag instead of
// the line's segments, and the display shows a repeated line there — the frame is delivered on
// time, degraded, never broken.
//
// Time is counted in segment words, not measured: which lines are repeated depends only on the
// segments of each line, so a frame is the same bytes on any machine and for any thread count.
// `wordsPerLine` is the geometry stage's rate, the words it sends per line period (seed 002: a
// 5 MHz segment rate over a 64 µs TV line, 320); 0 models a geometry stage that always keeps up.
#pragma once

#include <cstdint>
#include <deque>

namespace sv::segments {

struct ChannelTiming {
  int64_t wordsPerLine = 0;  // the geometry stage's rate; 0 = unlimited (no line is repeated)
  int criticalLines = 2;     // fewer lines buffered than this before a line: it is repeated
  int64_t fifoWords = 4096;  // the FIFO's capacity in segment words (seed 002: 4096)
};

class ChannelClock {
 public:
  // One field of `lines` lines, read by the display at line periods criticalLines, criticalLines
  // + 1, … after the geometry stage starts (the FIFO's prefill).
  ChannelClock(const ChannelTiming& timing, int lines);

  // Before line j (j = 0, 1, … in order): true when the geometry stage makes its segments; false
  // when fewer than criticalLines lines are buffered, and a repeat flag (one word) is sent.
  bool startLine(int j);
  // After line j's segments were made: `words` of them, its end-of-line word included, produced at
  // the stage's rate and queued as the FIFO has room. True when the last word is in the FIFO
  // before the display reads the line; false when it would come late (or the line is larger than
  // the FIFO): then a repeat flag goes instead, and the line is repeated.
  bool finishLine(int j, int64_t words);

 private:
  // Lines the display has read by time t: those with readAt(k) ≤ t.
  int64_t readBy(int64_t t) const;
  int64_t readAt(int64_t k) const { return (timing_.criticalLines + k) * timing_.wordsPerLine; }
  void queue(int j, int64_t words);

  ChannelTiming timing_;
  int lines_;
  int64_t t_ = 0;  // the geometry stage's time, in words
  struct Queued {
    int line;
    int64_t words;
  };
  std::deque<Queued> fifo_;  // lines in the FIFO, not yet read
  int64_t fifoWords_ = 0;
};

}  // namespace sv::segments
