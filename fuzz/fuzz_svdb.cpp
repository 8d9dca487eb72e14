// Fuzz target: the prepared database reader on arbitrary bytes (fuzz/README.md). The checksum of
// a mutated file is repaired first, and its payload size, (as the PNG targets repair CRCs), so that mutations reach the
// records rather than stop at the checksum.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "formats/svdb.h"
#include "fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace sv::formats;
  std::string bytes(reinterpret_cast<const char*>(data), size);
  if (bytes.size() >= detail::kDatabaseHeaderBytes) {
    const uint64_t payload = bytes.size() - detail::kDatabaseHeaderBytes;
    std::memcpy(bytes.data() + detail::kDatabasePayloadBytesAt, &payload, 8);
    const uint64_t sum = detail::databaseChecksum(bytes.data() + detail::kDatabaseHeaderBytes,
                                                  bytes.size() - detail::kDatabaseHeaderBytes);
    std::memcpy(bytes.data() + detail::kDatabaseChecksumAt, &sum, 8);
  }
  fuzz::checkResult(parseDatabase(bytes.data(), bytes.size(), "/nonexistent-synthvis-fuzz/db.svdb",
                                  fuzz::fuzzOptions()));
  return 0;
}
