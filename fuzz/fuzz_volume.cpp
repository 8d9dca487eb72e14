// Fuzz target: the volume readers (parseVolume: NIfTI-1 and NRRD, raw or gzip) on arbitrary bytes,
// as a .nii, a .nii.gz and a .nrrd. Beyond "no crash, no sanitizer report": a read grid keeps the
// promises of synthvis/volumes.h (sides 2 … kMaxVolumeSide, as many codes as samples, positive
// finite spacing and scale), and a failure carries a message.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "synthvis/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  for (const char* name : {"/nonexistent/fuzz.nii", "/nonexistent/fuzz.nii.gz", "/nonexistent/fuzz.nrrd"}) {
    const auto r = sv::scene::parseVolume(bytes, name, false);
    if (!r.ok()) {
      if (r.error().message.empty()) std::abort();
      continue;
    }
    const sv::scene::VolumeGrid& g = r.value();
    const bool ok = g.nx >= 2 && g.ny >= 2 && g.nz >= 2 && g.nx <= sv::scene::kMaxVolumeSide &&
                    g.ny <= sv::scene::kMaxVolumeSide && g.nz <= sv::scene::kMaxVolumeSide &&
                    g.codes.size() == size_t(g.nx) * size_t(g.ny) * size_t(g.nz) &&
                    g.scale > 0 && std::isfinite(g.scale) && std::isfinite(g.offset) &&
                    g.spacing.x > 0 && g.spacing.y > 0 && g.spacing.z > 0 &&
                    sv::isFinite(g.spacing);
    if (!ok) {
      std::fprintf(stderr, "bad grid: %d × %d × %d, %zu codes, scale %g\n", g.nx, g.ny, g.nz,
                   g.codes.size(), double(g.scale));
      std::abort();
    }
  }
  return 0;
}
