// Errors as values (STYLE.md habit 9): input errors carry the file and the problem, and the CLI
// turns them into one clear line. No exceptions cross the library's public API.
#pragma once

#include <optional>
#include <string>
#include <utility>

namespace sv {

// One input error: where (file, and a line:column or other position when known) and what.
struct Error {
  std::string file;      // the file the problem is in; empty for in-memory input
  std::string position;  // "12:7", "byte 1044", "accessor 3"… or empty
  std::string message;   // what is wrong, lower case, no trailing period

  // "scene.json:12:7: expected number" — the one line the CLI prints.
  // "file:position: message", "file: message", or just the message when no file is involved
  // (an option, a renderer).
  std::string str() const {
    if (file.empty()) return message;
    std::string s = file;
    if (!position.empty()) s += ":" + position;
    return s + ": " + message;
  }
};

// Either a value or an Error.
template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : value_(std::move(value)) {}      // NOLINT: implicit by design
  Result(Error error) : error_(std::move(error)) {}  // NOLINT: implicit by design

  bool ok() const { return value_.has_value(); }
  explicit operator bool() const { return ok(); }
  T& value() & { return *value_; }
  const T& value() const& { return *value_; }
  T&& value() && { return std::move(*value_); }
  T* operator->() { return &*value_; }
  const T* operator->() const { return &*value_; }
  const Error& error() const { return error_; }

 private:
  std::optional<T> value_;
  Error error_;
};

// Result without a value.
class [[nodiscard]] Status {
 public:
  Status() = default;
  Status(Error error) : error_(std::move(error)), failed_(true) {}  // NOLINT
  bool ok() const { return !failed_; }
  explicit operator bool() const { return ok(); }
  const Error& error() const { return error_; }

 private:
  Error error_;
  bool failed_ = false;
};

}  // namespace sv
