// Fuzz target: the height-field loaders (terrain/load_heights.cpp) on arbitrary bytes. The first
// byte chooses the reader, the rest is the file:
//   even       decodePng16 (our PNG codec; the chunks' CRCs made to match, png_crc.h);
//   1 mod 4    loadGdalFromMemory as "fuzz.tif" (GDAL's in-memory drivers: GTiff, AAIGrid, …);
//   3 mod 4    loadGdalFromMemory as "N45E006.hgt" (the SRTMHGT driver goes by the name).
// Both under a budget of 2^20 samples, so that no input costs more than a few megabytes.
// Beyond "no crash, no sanitizer report, no hang": a loaded table has its stated size within the
// budget, a finite positive placement and scale, and (PNG) exactly the caller's placement; a
// failure carries a one-line message.
#include <cpl_conv.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "formats/heights.h"
#include "png_crc.h"

namespace {

constexpr int64_t kBudget = int64_t(1) << 20;

void check(bool ok, const char* what) {
  if (ok) return;
  std::fprintf(stderr, "broken promise: %s\n", what);
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  namespace tr = sv::formats;
  // GDAL's block cache, process-wide, small: inputs are small and the fuzzer's RSS limit counts it.
  static const bool configured = [] {
    CPLSetConfigOption("GDAL_CACHEMAX", "16");  // MB
    return true;
  }();
  (void)configured;
  if (size < 1) return 0;
  const uint8_t selector = data[0];
  const tr::PngPlacement placement{-150, 320, 30, 25, -12, 0.5};
  const sv::Result<tr::HeightField> r = [&]() -> sv::Result<tr::HeightField> {
    if (selector % 2 == 0) {
      const std::vector<uint8_t> png = sv::fuzz::withPngCrcs(data + 1, size - 1);
      return tr::decodePng16(png.data(), png.size(), "fuzz.png", placement, kBudget);
    }
    const std::string bytes(reinterpret_cast<const char*>(data + 1), size - 1);
    return tr::loadGdalFromMemory(bytes, selector % 4 == 1 ? "fuzz.tif" : "N45E006.hgt", kBudget);
  }();
  if (!r.ok()) {
    const std::string line = r.error().str();
    check(!r.error().message.empty() && line.find('\n') == std::string::npos,
          "an error is one line with a message");
    return 0;
  }
  const tr::HeightField& f = r.value();
  check(f.width >= 2 && f.height >= 2 && int64_t(f.width) * f.height <= kBudget,
        "the size is within the budget");
  check(f.q.size() == size_t(f.width) * size_t(f.height), "the table holds width × height codes");
  check(std::isfinite(f.originU) && std::isfinite(f.originV) && f.spacingU > 0 && f.spacingV > 0 &&
            std::isfinite(f.spacingU) && std::isfinite(f.spacingV),
        "the placement is finite with positive spacing");
  check(std::isfinite(f.offset) && f.scale > 0 && std::isfinite(f.scale),
        "heights have a finite offset and positive scale");
  check(std::isfinite(f.eastU()) && std::isfinite(f.southV()), "the extent is finite");
  if (selector % 2 == 0)
    check(f.originU == placement.originU && f.originV == placement.originV &&
              f.spacingU == placement.spacingU && f.spacingV == placement.spacingV &&
              f.offset == placement.offset && f.scale == placement.scale,
          "a PNG table is placed as the caller said");
  return 0;
}
