#include "core/write_file.h"

#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace sv::core {

const char* writeFailure(int error) { return std::strerror(error ? error : EIO); }

Status writeFile(const std::string& path, std::initializer_list<std::string_view> parts) {
  auto failed = [&path](int error) {
    return Error{path, "", fmt::format("cannot write: {}", writeFailure(error))};
  };
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return failed(errno);
  for (std::string_view part : parts)
    if (!part.empty() && std::fwrite(part.data(), 1, part.size(), f) != part.size()) {
      const int error = errno;
      std::fclose(f);
      return failed(error);
    }
  if (std::fflush(f) != 0) {
    const int error = errno;
    std::fclose(f);
    return failed(error);
  }
  // close can still fail (a network file system reports there), and then the file is not whole.
  if (std::fclose(f) != 0) return failed(errno);
  return {};
}

}  // namespace sv::core
