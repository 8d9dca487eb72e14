// Fuzz target: the star catalogue reader (parseStarCatalog, xplanet's BSC format) on arbitrary
// text. Beyond "no crash, no sanitizer report": a read catalogue holds unit directions, finite
// magnitudes in range and finite colours, and a failure carries a message.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "synthvis/formats.h"
#include "synthvis/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto r = sv::formats::parseStarCatalog(text, "fuzz.BSC");
  if (!r.ok()) {
    if (r.error().message.empty()) std::abort();
    return 0;
  }
  for (const sv::scene::Star& s : r.value()) {
    const float len = sv::length(s.direction);
    if (!(std::fabs(len - 1) < 1e-4f) || !(std::fabs(s.magnitude) <= 30) ||
        !sv::isFinite(s.color)) {
      std::fprintf(stderr, "bad star: |d| %g, magnitude %g\n", double(len), double(s.magnitude));
      std::abort();
    }
  }
  return 0;
}
