// The priority X-sort of seed 002 (SPEC §10): bucket sorting by overwrite in a sorter memory of one
// word per X position, each a segment number and a mark. Segments arrive in increasing priority,
// each writing its number over X_L … X_R − 1, setting the marks at X_L and X_R and clearing those
// between; afterwards the marked addresses are the RUN codes — the positions where the visible
// segment changes — and the words there name the segment visible from each to the next.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace sv::segments {

// One run of a line: the segment visible over [x, next run's x), or to the line's end.
struct Run {
  int32_t x = 0;
  uint32_t segment = 0;
};

class XSorter {
 public:
  // A sorter for lines of `width` pixels (≥ 1): width + 1 words, the last one holding only the
  // mark at X_R = width.
  explicit XSorter(int width);

  int width() const { return int(words_.size()) - 1; }

  // A new line: every word `background`, no mark.
  void clear(uint32_t background);
  // Writes segment number `segment` over [xl, xr) (clipped to the line; nothing when empty): the
  // latest written wins, so segments come in increasing priority.
  void add(uint32_t segment, int xl, int xr);
  // The line's RUN codes in increasing X, the first at X = 0 whatever its mark: a run per change
  // of the visible segment, exactly — a mark is set only where two different segments meet, and
  // every such place keeps the mark its last writer set.
  void runs(std::vector<Run>& out) const;
  // The segment visible at x (the word's number).
  uint32_t at(int x) const { return words_[size_t(x)] & kNumber; }

 private:
  static constexpr uint32_t kMark = 1u << 31, kNumber = kMark - 1;
  std::vector<uint32_t> words_;  // the seed's words: number in the low 31 bits, mark in the top
};

}  // namespace sv::segments
