// The long tail of model formats (AC3D — FlightGear's —, COLLADA, 3DS, FBX, PLY, STL, …) through
// Assimp, run in a child process: Assimp is not hardened against malformed input, so a crash, a
// hang or an unbounded allocation in it must cost only that child. The child converts Assimp's
// scene to ours and writes it as a binary glTF the parent then loads; every failure — Assimp's
// error, a signal, the time limit — becomes one line naming the file.
#pragma once

#include <string>

#include "formats/reader.h"

namespace sv::formats::detail {

// Loads `path` with Assimp (libassimp.so.5, opened in the child only, so that its libraries'
// symbols never meet ours). `extension` is the file's, lower case, for the unsupported-type
// message.
Result<Scene> loadWithAssimp(const std::string& path, const std::string& extension,
                             const LoadOptions& options);

}  // namespace sv::formats::detail
