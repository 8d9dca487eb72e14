// Whole files and paths: the one place synthvis reads an input file, writes an output file and
// takes a path apart.
//
// Reading is bounded and refuses what is not a regular file, so that no input — a scene, a host
// script, an IG configuration — can make a reader hang on a device or allocate without bound.
// Writing reports every failure: a buffered write only fails when the buffer is flushed, often at
// close, so a writer that checks only fwrite or an ofstream's state reports success for a file a
// full disk cut short (`synthvis gen -o x.glb` on a full disk: exit 0, a truncated file). Every
// output of synthvis that is bytes in memory goes out through here.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>

#include "synthvis/result.h"

namespace sv::core {

// Files larger than this are refused before anything is read: no input of synthvis has a reason
// to be this big, and reading it whole is exactly the allocation a size in the input must not
// cause.
inline constexpr uint64_t kMaxFileBytes = uint64_t(1) << 30;

// Reads a whole regular file of at most `maxBytes` (≤ kMaxFileBytes). Devices, pipes and
// directories are refused, so a reference such as "/dev/zero" cannot hang a reader. The error
// names `path`: "path: cannot open file: reason", "path: file is too large (…)".
Result<std::string> readFile(const std::string& path, uint64_t maxBytes = kMaxFileBytes);

// Writes the parts one after another to `path` (created or truncated), then flushes and closes
// it. Any failure — opening, writing, flushing, closing — is an Error naming the file and the
// system's reason: "out.glb: cannot write: No space left on device". What was written before the
// failure stays.
Status writeFile(const std::string& path, std::initializer_list<std::string_view> parts);

// The system's reason for a failed write: strerror(error), or that of EIO where the failing call
// set no errno (a short fwrite may not), so that no error ever reads "Success".
const char* writeFailure(int error);

// Paths, taken apart lexically (std::filesystem's rules; no file is opened):
// the directory part of `path` ("" when it has none: "scene.json"; "/" for "/scene.json");
std::string directoryOf(const std::string& path);
// `ref` resolved against directory `base`: absolute references are kept, relative ones joined
// ("" as `base` keeps `ref` relative to the working directory); the result is normalized. A
// reference written with Windows separators (".\\textures\\wall.jpg", as exporters on Windows
// write them) is read with '/' for '\\' — a file name with a backslash in it is not portable.
std::string resolvePath(const std::string& base, const std::string& ref);
// The extension of `path` in lower case, with its dot (".json"), or "".
std::string lowerExtension(const std::string& path);
// The file name part of `path` ("dem.tif" of "maps/dem.tif"; "" for "maps/").
std::string fileName(const std::string& path);
// `path` with "-" + `suffix` before its extension: out.png → out-left.png (out → out-left).
std::string withSuffix(const std::string& path, const std::string& suffix);
// A stable key for "the same file": the canonical path when it can be computed, else `path`.
std::string canonicalKey(const std::string& path);

// A part of bytes that are not chars.
inline std::string_view bytesOf(const void* data, size_t size) {
  return {static_cast<const char*>(data), size};
}

}  // namespace sv::core
