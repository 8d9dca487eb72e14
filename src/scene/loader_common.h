// Plumbing shared by the scene loaders: bounded file reading, path handling, one-line messages and
// the context that carries limits and open files through nested loads.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "synthvis/result.h"
#include "synthvis/scene.h"

namespace sv::scene::detail {

// Files larger than this are refused before anything is read: no scene file has a reason to be
// this big, and reading it whole is exactly the allocation a size in the input must not cause.
inline constexpr uint64_t kMaxFileBytes = uint64_t(1) << 30;

// Reads a whole regular file. Devices, pipes and directories are refused, so a reference such as
// "/dev/zero" cannot hang a loader. The error names `path`: "path: cannot open file: reason".
Result<std::string> readFile(const std::string& path);

// The directory part of `path` ("" when it has none).
std::string directoryOf(const std::string& path);
// `ref` resolved against directory `base`: absolute references are kept, relative ones joined.
std::string resolvePath(const std::string& base, const std::string& ref);
// The extension of `path` in lower case, with its dot (".json"), or "".
std::string lowerExtension(const std::string& path);
// A stable key for "the same file": the canonical path when it can be computed, else `path`.
std::string canonicalKey(const std::string& path);

// Collapses a library's multi-line message into one line: trims, joins lines with "; ".
std::string oneLine(const std::string& text);

// The polygon `p`, possibly concave, as triangles (indices into `p`) by ear clipping in the plane
// of its Newell normal, wound as the outline is; an outline that leaves no ear (self-intersecting,
// or degenerate) is closed by a fan of what remains. O(n²) at worst.
std::vector<uint32_t> triangulatePolygon(const std::vector<Vec3>& p);

// The switches, degrees of freedom and light points of `other`, whose instances were appended to
// `scene` from index `instanceBase` on, placed by `transform` (appendScene, and scene files that
// place other files).
void appendArticulationsAndLights(Scene& scene, const Scene& other, const Mat4& transform,
                                  uint32_t instanceBase);

// The state of one top-level load, passed down through scene files that reference others.
struct LoadContext {
  LoadOptions options;
  // canonicalKey of every JSON scene currently being parsed, outermost first: finds cycles and
  // measures nesting.
  std::vector<std::string> openScenes;
  // Files already loaded during this load, by canonicalKey, so that a file referenced many times
  // is read and parsed once.
  std::map<std::string, Scene> loaded;
};

// Loads `path` by its extension (.json, .gltf, .glb, .obj, .flt; others through Assimp) within
// `context`.
Result<Scene> loadFile(const std::string& path, LoadContext& context);
// The OpenFlight reader proper (openflight_loader.cpp): external references load through
// `context`.
Result<Scene> parseOpenFlightIn(const std::string& bytes, const std::string& path,
                                LoadContext& context);
// The JSON scene parser proper (json_loader.cpp).
Result<Scene> parseJsonSceneIn(const std::string& text, const std::string& path,
                               LoadContext& context);

}  // namespace sv::scene::detail
