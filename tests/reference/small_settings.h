// Shared by the reference tests: a small, quick bench configuration.
#pragma once

#include "synthvis/bench.h"

namespace sv::reference::testing {

inline BenchSettings smallSettings() {
  BenchSettings s;
  s.options.width = 320;
  s.options.height = 240;
  s.options.threads = 2;
  s.frames = 2;
  s.warmup = 1;
  return s;
}

}  // namespace sv::reference::testing
