// What every scene fuzz target checks beyond "no crash, no sanitizer report": a loaded scene
// keeps the promises of scene.h (validate passes, the triangle budget holds), and a failure comes
// with a message. A broken promise aborts, which libFuzzer and the replay driver report.
#pragma once

#include <cstdio>
#include <cstdlib>

#include "synthvis/scene.h"

namespace sv::scene::fuzz {

// Limits for fuzzing: no file access at all, and a triangle budget small enough that the largest
// accepted input still runs in milliseconds. The paths the targets pass name a directory that
// does not exist, so even a relative reference could resolve to nothing.
inline LoadOptions fuzzOptions() {
  LoadOptions options;
  options.followReferences = false;
  options.maxTriangles = uint64_t(1) << 18;
  options.maxTexels = uint64_t(1) << 20;  // generated and embedded textures: 8 MB at most
  return options;
}

inline void checkResult(const Result<Scene>& result) {
  if (!result.ok()) {
    if (result.error().message.empty()) {
      std::fprintf(stderr, "error without a message: %s\n", result.error().str().c_str());
      std::abort();
    }
    return;
  }
  Status valid = validate(result.value(), "fuzz");
  if (!valid.ok()) {
    std::fprintf(stderr, "loaded scene is invalid: %s\n", valid.error().str().c_str());
    std::abort();
  }
  if (result.value().triangleCount() > fuzzOptions().maxTriangles) {
    std::fprintf(stderr, "triangle budget exceeded: %zu\n", result.value().triangleCount());
    std::abort();
  }
}

}  // namespace sv::scene::fuzz
