// Fuzz target: OpenVDB files (parseVolume on bytes named .vdb), read by the OpenVDB library in the
// forked child of scene/openvdb_loader.h — so what is fuzzed here is the isolation (a crash, hang
// or runaway allocation of OpenVDB's must become a one-line error, never the fuzzer's finding)
// and the exchange with the child, not OpenVDB itself (not instrumented). A budget of 2^20
// samples, since a short file may describe a large grid, keeps the child's memory limit small.
// Beyond "no crash, no sanitizer report": fuzz_check.h's checkVolume.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_check.h"
#include "synthvis/formats.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  constexpr size_t kBudget = size_t(1) << 20;
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  sv::formats::fuzz::checkVolume(
      sv::formats::parseVolume(bytes, "/nonexistent/fuzz.vdb", false, kBudget), kBudget);
  return 0;
}
