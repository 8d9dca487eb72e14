// loadScene: choosing a loader by file extension, and the file and path helpers all loaders share.
#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <new>

#include "scene/assimp_loader.h"
#include "scene/loader_common.h"

namespace sv::scene {
namespace detail {

namespace fs = std::filesystem;

Result<std::string> readFile(const std::string& path) {
  auto fail = [&](const std::string& why) {
    return Error{path, "", fmt::format("cannot open file: {}", why)};
  };
  // Step 1: look before opening, so that only regular files are ever read.
  std::error_code ec;
  fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) return fail("no such file");
  if (fs::is_directory(status)) return fail("is a directory");
  if (!fs::is_regular_file(status)) return fail("not a regular file");
  uintmax_t size = fs::file_size(path, ec);
  if (ec) return fail(ec.message());
  if (size > kMaxFileBytes)
    return Error{path, "",
                 fmt::format("file is too large ({} bytes, the limit is {})", size, kMaxFileBytes)};

  // Step 2: read it whole. The size was checked above; a file that grows meanwhile is read only
  // up to that size plus one byte, which is enough to notice.
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"),
                                                       &std::fclose);
  if (!file) return fail(std::strerror(errno));
  std::string bytes(static_cast<size_t>(size), '\0');
  size_t got = size ? std::fread(bytes.data(), 1, bytes.size(), file.get()) : 0;
  if (got != bytes.size() || std::ferror(file.get())) return fail("read error");
  return bytes;
}

std::string directoryOf(const std::string& path) { return fs::path(path).parent_path().string(); }

std::string resolvePath(const std::string& base, const std::string& ref) {
  fs::path r(ref);
  if (r.is_absolute() || base.empty()) return r.lexically_normal().string();
  return (fs::path(base) / r).lexically_normal().string();
}

std::string lowerExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return ext;
}

std::string canonicalKey(const std::string& path) {
  std::error_code ec;
  fs::path canonical = fs::weakly_canonical(fs::path(path), ec);
  return ec ? fs::path(path).lexically_normal().string() : canonical.string();
}

std::string oneLine(const std::string& text) {
  std::string out;
  size_t start = 0;
  while (start <= text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    // Trim blanks and the '\r' of CRLF text.
    size_t a = line.find_first_not_of(" \t\r");
    size_t b = line.find_last_not_of(" \t\r");
    if (a != std::string::npos) {
      if (!out.empty()) out += "; ";
      out += line.substr(a, b - a + 1);
    }
    start = end + 1;
  }
  // A library may repeat itself over many lines; one line should stay readable.
  constexpr size_t kMaxLength = 400;
  if (out.size() > kMaxLength) out = out.substr(0, kMaxLength) + "…";
  return out;
}

Result<Scene> loadFile(const std::string& path, LoadContext& context) {
  std::string ext = lowerExtension(path);
  if (ext == ".svdb") return loadDatabase(path, context.options);
  // Other formats (AC3D, COLLADA, 3DS, FBX, PLY, STL, …) through Assimp in a child process.
  if (ext != ".json" && ext != ".gltf" && ext != ".glb" && ext != ".obj" && ext != ".flt") {
    if (Result<std::string> bytes = readFile(path); !bytes) return bytes.error();
    return loadWithAssimp(path, ext, context.options);
  }
  Result<std::string> bytes = readFile(path);
  if (!bytes) return bytes.error();
  if (ext == ".json") return parseJsonSceneIn(bytes.value(), path, context);
  if (ext == ".obj") return parseObj(bytes.value(), path, context.options);
  if (ext == ".flt") return parseOpenFlightIn(bytes.value(), path, context);
  return loadGltfFromMemory(bytes.value(), path, context.options);
}

}  // namespace detail

Result<Scene> loadScene(const std::string& path) { return loadScene(path, LoadOptions{}); }

Result<Scene> loadScene(const std::string& path, const LoadOptions& options) {
  // The loaders report input errors as values; what can still be thrown here is the standard
  // library running out of memory, which becomes one more error value.
  try {
    detail::LoadContext context{options, {}, {}};
    Result<Scene> scene = detail::loadFile(path, context);
    if (!scene) return scene;
    // The traversal's hierarchy over the file's instances (they do not move once loaded); a
    // prepared database brings its own.
    const Scene& loaded = scene.value();
    if (!loaded.instanceTree || loaded.instanceTree->instanceCount != loaded.instances.size())
      buildInstanceTree(scene.value());
    const Scene& s = scene.value();
    if (s.triangleCount() == 0 && s.freeForms.empty() && s.terrains.empty() &&
        s.lightPoints.empty() && s.stars.stars.empty() && s.lines.empty())
      scene.value().warnings.push_back(fmt::format("{}: nothing to draw", path));
    return scene;
  } catch (const std::bad_alloc&) {
    return Error{path, "", "out of memory"};
  } catch (const std::exception& e) {
    return Error{path, "", e.what()};
  }
}

}  // namespace sv::scene
