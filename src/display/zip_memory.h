// Zip archives in memory through minizip (Debian's libminizip, zlib's contrib): the reader of
// entries with every size bounded before it is allocated, and the writer of deflated entries.
// Used by the MPCDI reader and writer (display/mpcdi.h).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace sv::display::detail {

// Thrown inside the display stage's readers and caught at their API (no exception leaves the
// library): `position` is the zip entry (and line), `message` the problem.
struct Problem {
  std::string position;
  std::string message;
};

struct ZipStream;  // the bytes minizip reads or writes (zip_memory.cpp)

class ZipReader {
 public:
  // Opens the archive in `bytes` (kept by reference: it must outlive the reader). Throws Problem
  // when it is not a zip archive or holds more than `maxEntries` entries.
  ZipReader(const std::string& bytes, int maxEntries);
  ~ZipReader();
  ZipReader(const ZipReader&) = delete;
  ZipReader& operator=(const ZipReader&) = delete;

  bool has(const std::string& entry);
  // The decompressed bytes of `entry`. Throws Problem (position: the entry) when it is missing,
  // encrypted, compressed other than stored or deflate, declares or inflates to more than
  // `maxBytes`, inflates to another size than it declares, or fails its CRC.
  std::string read(const std::string& entry, uint64_t maxBytes);

 private:
  ZipStream* stream_;
  void* zip_ = nullptr;
};

// The archive of (name, bytes) entries, deflated, in the given order, with a fixed timestamp so
// that the same entries give the same bytes. Throws Problem when minizip fails.
std::string writeZip(const std::vector<std::pair<std::string, std::string>>& entries);

}  // namespace sv::display::detail
