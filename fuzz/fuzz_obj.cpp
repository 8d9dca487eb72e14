// Fuzz target: the Wavefront OBJ loader on arbitrary text (fuzz/README.md).
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace sv::formats;
  std::string text(reinterpret_cast<const char*>(data), size);
  fuzz::checkResult(parseObj(text, "/nonexistent-synthvis-fuzz/model.obj", fuzz::fuzzOptions()));
  return 0;
}
