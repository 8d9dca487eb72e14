// loadScene: choosing a reader by file extension, and the helpers all readers share.
#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <new>

#include "formats/assimp_reader.h"
#include "formats/reader.h"
#include "formats/svdb.h"

namespace sv::formats {
namespace detail {

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

}  // namespace sv::formats
