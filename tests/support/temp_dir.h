// Temporary files for tests. ctest runs every test as a process of its own, two or more at a
// time, and two suites (Release, sanitizers) may share a machine: a fixed name under /tmp is
// shared between them, and one test's cleanup once deleted another's file while it was read
// (CI of stop 47: "not an OpenVDB file"). Every test file therefore lives in a directory of its
// process's own.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

// Not `sv::testing`: inside namespace sv that name would hide GoogleTest's ::testing.
namespace sv::tests {

// A fresh directory under the system temp directory, named by the process and a random number,
// removed with everything in it at scope exit.
class TempDir {
 public:
  TempDir() {
    std::random_device random;
    path_ = std::filesystem::temp_directory_path() /
            ("synthvis-test-" + std::to_string(::getpid()) + "-" + std::to_string(random()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& dir() const { return path_; }
  std::string path(const std::string& name) const { return (path_ / name).string(); }

  // Writes `bytes` to `name` inside the directory (making its folders) and returns its path.
  std::string write(const std::string& name, const std::string& bytes) const {
    const std::filesystem::path p = path_ / name;
    std::filesystem::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
    return p.string();
  }

 private:
  std::filesystem::path path_;
};

// The running process's own directory: made on first use, removed when the process exits.
inline const TempDir& processTemp() {
  static const TempDir dir;
  return dir;
}

// A file that takes any open but no data: `name` in the process's directory, a link to /dev/full
// (every write to it fails with "No space left on device" when it is flushed). Empty where there
// is no such device; the test then skips.
inline std::string fullDiskPath(const std::string& name) {
  std::error_code ec;
  if (!std::filesystem::is_character_file("/dev/full", ec)) return {};
  const std::string path = processTemp().path(name);
  std::filesystem::remove(path, ec);
  std::filesystem::create_symlink("/dev/full", path, ec);
  return ec ? std::string() : path;
}

}  // namespace sv::tests
