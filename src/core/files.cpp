#include "synthvis/files.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>

namespace sv::core {

namespace fs = std::filesystem;

Result<std::string> readFile(const std::string& path, uint64_t maxBytes) {
  auto fail = [&](const std::string& why) {
    return Error{path, "", fmt::format("cannot open file: {}", why)};
  };
  maxBytes = std::min(maxBytes, kMaxFileBytes);
  // Step 1: look before opening, so that only regular files are ever read.
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) return fail("no such file");
  if (fs::is_directory(status)) return fail("is a directory");
  if (!fs::is_regular_file(status)) return fail("not a regular file");
  const uintmax_t size = fs::file_size(path, ec);
  if (ec) return fail(ec.message());
  if (size > maxBytes)
    return Error{path, "",
                 fmt::format("file is too large ({} bytes, the limit is {})", size, maxBytes)};

  // Step 2: read it whole. The size was checked above; a file that grows meanwhile is read only
  // up to that size, which is enough to notice.
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"),
                                                       &std::fclose);
  if (!file) return fail(std::strerror(errno));
  std::string bytes(static_cast<size_t>(size), '\0');
  const size_t got = size ? std::fread(bytes.data(), 1, bytes.size(), file.get()) : 0;
  if (got != bytes.size() || std::ferror(file.get())) return fail("read error");
  return bytes;
}

std::string directoryOf(const std::string& path) { return fs::path(path).parent_path().string(); }

std::string resolvePath(const std::string& base, const std::string& ref) {
  std::string portable = ref;
  std::replace(portable.begin(), portable.end(), '\\', '/');
  const fs::path r(portable);
  if (r.is_absolute() || base.empty()) return r.lexically_normal().string();
  return (fs::path(base) / r).lexically_normal().string();
}

std::string lowerExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return ext;
}

std::string fileName(const std::string& path) { return fs::path(path).filename().string(); }

std::string withSuffix(const std::string& path, const std::string& suffix) {
  const fs::path p(path);
  if (!p.has_extension()) return path + "-" + suffix;
  fs::path out = p;
  out.replace_filename(p.stem().string() + "-" + suffix + p.extension().string());
  return out.string();
}

std::string canonicalKey(const std::string& path) {
  std::error_code ec;
  const fs::path canonical = fs::weakly_canonical(fs::path(path), ec);
  return ec ? fs::path(path).lexically_normal().string() : canonical.string();
}

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
