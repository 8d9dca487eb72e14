// The clock every stage times itself by (FrameStats' milliseconds, the bench harness).
#pragma once

#include <chrono>

namespace sv::core {

using Clock = std::chrono::steady_clock;

// Milliseconds from `t0` to now.
inline double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

}  // namespace sv::core
