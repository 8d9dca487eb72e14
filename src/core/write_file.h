// Writing a whole file, with every failure reported. A buffered write only fails when the buffer
// is flushed, often at close, so a writer that checks only fwrite or an ofstream's state reports
// success for a file a full disk cut short (`synthvis gen -o x.glb` on a full disk: exit 0, a
// truncated file). Every output of synthvis that is bytes in memory goes out through here.
#pragma once

#include <initializer_list>
#include <string>
#include <string_view>

#include "synthvis/result.h"

namespace sv::core {

// Writes the parts one after another to `path` (created or truncated), then flushes and closes
// it. Any failure — opening, writing, flushing, closing — is an Error naming the file and the
// system's reason: "out.glb: cannot write: No space left on device". What was written before the
// failure stays.
Status writeFile(const std::string& path, std::initializer_list<std::string_view> parts);

// The system's reason for a failed write: strerror(error), or that of EIO where the failing call
// set no errno (a short fwrite may not), so that no error ever reads "Success".
const char* writeFailure(int error);

// A part of bytes that are not chars.
inline std::string_view bytesOf(const void* data, size_t size) {
  return {static_cast<const char*>(data), size};
}

}  // namespace sv::core
