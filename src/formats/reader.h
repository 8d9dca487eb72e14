// Plumbing shared by the readers: one-line messages, polygons as triangles, and the context that
// carries limits and open files through nested loads. Files and paths are core's (synthvis/files.h:
// bounded reading, the one path helper).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "scene/append.h"
#include "synthvis/files.h"
#include "synthvis/formats.h"
#include "synthvis/result.h"
#include "synthvis/scene.h"

namespace sv::formats {
// The readers build the database's records throughout.
using namespace sv::scene;  // NOLINT(google-build-using-namespace)
}  // namespace sv::formats

namespace sv::formats::detail {

using core::canonicalKey;
using core::directoryOf;
using core::kMaxFileBytes;
using core::lowerExtension;
using core::readFile;
using core::resolvePath;

// Collapses a library's multi-line message into one line: trims, joins lines with "; ".
std::string oneLine(const std::string& text);

// The polygon `p`, possibly concave, as triangles (indices into `p`) by ear clipping in the plane
// of its Newell normal, wound as the outline is; an outline that leaves no ear (self-intersecting,
// or degenerate) is closed by a fan of what remains. O(n²) at worst.
std::vector<uint32_t> triangulatePolygon(const std::vector<Vec3>& p);

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

}  // namespace sv::formats::detail
