// Fuzz target: the OpenFlight reader on arbitrary bytes (fuzz/README.md).
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace sv::formats;
  std::string bytes(reinterpret_cast<const char*>(data), size);
  fuzz::checkResult(
      parseOpenFlight(bytes, "/nonexistent-synthvis-fuzz/model.flt", fuzz::fuzzOptions()));
  return 0;
}
