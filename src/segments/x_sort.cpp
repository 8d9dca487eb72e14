// Based on: SPEC §10 (seed 002: the priority X-sort by bucket sorting with overwrite, the marked
// addresses as RUN codes).
#include "segments/x_sort.h"

#include <algorithm>

#include "core/check.h"

namespace sv::segments {

XSorter::XSorter(int width) : words_(size_t(std::max(width, 1)) + 1, 0) { SV_CHECK(width >= 1); }

void XSorter::clear(uint32_t background) {
  SV_CHECK(background <= kNumber);
  std::fill(words_.begin(), words_.end(), background);
}

void XSorter::add(uint32_t segment, int xl, int xr) {
  SV_CHECK(segment <= kNumber);
  xl = std::max(xl, 0);
  xr = std::min(xr, width());
  if (xl >= xr) return;
  // X_L: number and mark; X_L+1 … X_R−1: number, mark cleared; X_R: mark only.
  uint32_t* w = words_.data();
  w[xl] = segment | kMark;
  for (int x = xl + 1; x < xr; ++x) w[x] = segment;
  w[xr] |= kMark;
}

void XSorter::runs(std::vector<Run>& out) const {
  out.clear();
  const int w = width();
  out.push_back({0, at(0)});
  for (int x = 1; x < w; ++x)
    if (words_[size_t(x)] & kMark) out.push_back({x, at(x)});
}

}  // namespace sv::segments
