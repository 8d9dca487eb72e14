// The samples per pixel synthvis anti-aliases with (SPEC §5; docs/quality.md): the one list the
// renderer's options, the rasterizer's sample patterns, the resolve and every parser and help text
// take their counts from. 1 is point sampling at pixel centres.
#pragma once

#include <algorithm>
#include <array>
#include <string>

namespace sv {

inline constexpr std::array<int, 5> kSampleCounts = {1, 4, 8, 16, 64};

constexpr bool isSampleCount(int n) {
  return std::find(kSampleCounts.begin(), kSampleCounts.end(), n) != kSampleCounts.end();
}

// "1, 4, 8, 16 or 64", for messages and help.
inline std::string sampleCountNames() {
  std::string s;
  for (size_t i = 0; i < kSampleCounts.size(); ++i) {
    if (i > 0) s += i + 1 < kSampleCounts.size() ? ", " : " or ";
    s += std::to_string(kSampleCounts[i]);
  }
  return s;
}

}  // namespace sv
