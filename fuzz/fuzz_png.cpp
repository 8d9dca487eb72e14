// Fuzz target: the PNG reader (decodePng, libpng's simplified API) on arbitrary bytes, with the
// chunks' CRCs made to match (png_crc.h).
// Beyond "no crash, no sanitizer report": a decoded image has a sane size and exactly
// width·height·3 bytes, and a failure carries a message.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "png_crc.h"
#include "synthvis/image.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::vector<uint8_t> bytes = sv::fuzz::withPngCrcs(data, size);
  const sv::Result<sv::Image> r = sv::decodePng(bytes.data(), bytes.size(), "fuzz.png");
  if (!r.ok()) {
    if (r.error().message.empty()) std::abort();
    return 0;
  }
  if (r->width <= 0 || r->height <= 0 || r->width > 8192 || r->height > 8192 ||
      r->rgb.size() != size_t(r->width) * r->height * 3) {
    std::fprintf(stderr, "bad image %dx%d with %zu bytes\n", r->width, r->height, r->rgb.size());
    std::abort();
  }
  return 0;
}
