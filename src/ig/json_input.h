// The IG's two JSON inputs — its configuration and the scripted host's script — read the same
// way: the text parsed, then walked by a reader that throws BadField for a value it refuses; either
// failure becomes one Error naming the file.
#pragma once

#include <fmt/format.h>

#include <nlohmann/json.hpp>
#include <string>

#include "synthvis/files.h"
#include "synthvis/result.h"

namespace sv::ig {

struct BadField {
  std::string message;  // "rate: 1000 is outside [1, 240]"
};
[[noreturn]] inline void badField(const std::string& message) { throw BadField{message}; }

// `read(root)` → T, or the Error that the text, a refused field or a mistyped one makes.
template <class T, class Read>
Result<T> parseJsonInput(const std::string& text, const std::string& path, Read&& read) {
  nlohmann::json root;
  try {
    root = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    return Error{path, fmt::format("byte {}", e.byte), "malformed JSON"};
  } catch (const nlohmann::json::exception&) {
    return Error{path, "", "malformed JSON (a number out of range)"};
  }
  try {
    return read(root);
  } catch (const BadField& e) {
    return Error{path, "", e.message};
  } catch (const nlohmann::json::exception&) {
    return Error{path, "", "a field has the wrong type"};
  }
}

// A JSON input file's text, by the scene readers' rules (synthvis/files.h): a regular file only —
// a device such as /dev/zero or a pipe is refused before anything is read — of at most 1 MiB
// (these are hand-written files), its size checked before it is read.
inline Result<std::string> readJsonInput(const std::string& path) {
  return core::readFile(path, uint64_t(1) << 20);
}

}  // namespace sv::ig
