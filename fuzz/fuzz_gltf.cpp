// Fuzz target: the glTF loader on arbitrary bytes, as .gltf text or .glb by their magic
// (fuzz/README.md).
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace sv::formats;
  std::string bytes(reinterpret_cast<const char*>(data), size);
  fuzz::checkResult(
      loadGltfFromMemory(bytes, "/nonexistent-synthvis-fuzz/model.gltf", fuzz::fuzzOptions()));
  return 0;
}
