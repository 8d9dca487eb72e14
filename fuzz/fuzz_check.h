// What every scene fuzz target checks beyond "no crash, no sanitizer report": a loaded scene
// keeps the promises of scene.h (validate passes, the triangle budget holds), and a failure comes
// with a message. A broken promise aborts, which libFuzzer and the replay driver report.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>

#include "synthvis/formats.h"

namespace sv::formats::fuzz {

using scene::kMaxVolumeSide;
using scene::VolumeGrid;

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

// What the volume targets check of parseVolume's result: a read grid keeps the promises of
// synthvis/volumes.h (sides 2 … kMaxVolumeSide, as many codes as samples and no more than
// `maxSamples`, a positive finite scale and spacing), and a failure carries a message.
inline void checkVolume(const Result<VolumeGrid>& r, size_t maxSamples) {
  if (!r.ok()) {
    if (r.error().message.empty()) std::abort();
    return;
  }
  const VolumeGrid& g = r.value();
  const bool ok = g.nx >= 2 && g.ny >= 2 && g.nz >= 2 && g.nx <= kMaxVolumeSide &&
                  g.ny <= kMaxVolumeSide && g.nz <= kMaxVolumeSide &&
                  g.codes.size() == size_t(g.nx) * size_t(g.ny) * size_t(g.nz) &&
                  g.codes.size() <= maxSamples && g.scale > 0 && std::isfinite(g.scale) &&
                  std::isfinite(g.offset) && g.spacing.x > 0 && g.spacing.y > 0 &&
                  g.spacing.z > 0 && isFinite(g.spacing);
  if (!ok) {
    std::fprintf(stderr, "bad grid: %d × %d × %d, %zu codes, scale %g\n", g.nx, g.ny, g.nz,
                 g.codes.size(), double(g.scale));
    std::abort();
  }
}

}  // namespace sv::formats::fuzz
