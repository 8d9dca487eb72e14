// The database preparation system (SPEC §1; seed 004 names it beside the image generator): what
// `synthvis prep` does to a loaded scene before writing it as a prepared database
// (formats::saveDatabase) — docs/prep.md.
//
//   1. Optimize every mesh for the renderer (meshoptimizer): vertices deduplicated and put in the
//      order the triangles first use them (vertex fetch). Triangle order is kept: the image is
//      then bit-identical to the source's (the frame's samples do not depend on it, but
//      coplanar overlaps and translucency do).
//   2. Generate levels of detail where the source has none: every mesh of at least minTriangles
//      placed by instances without a level-of-detail group gets a group of up to maxLevels levels,
//      each simplified to about `reduction` of the one before (meshopt_simplify, topology kept),
//      switching where its geometric error projects to `pixelError` pixels on a `screenHeight`
//      pixel screen under the 60° view ranges refer to (scene.h LodGroup).
//   3. Build the instance tree (scene::buildInstanceTree), which the database stores (its merged
//      cells are made again on load).
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "synthvis/result.h"
#include "synthvis/scene.h"

namespace sv::prep {

struct PrepOptions {
  bool optimize = true;
  bool generateLods = true;
  int maxLevels = 4;            // per generated group, level 0 (the source mesh) included; 2…8
  float reduction = 0.25f;      // each level's triangles over the one before's, (0, 1)
  uint32_t minTriangles = 256;  // smaller meshes keep one level
  float pixelError = 1.0f;      // the projected error a level may show, pixels
  int screenHeight = 1080;
};

struct PrepReport {
  size_t meshes = 0, instances = 0;
  uint64_t trianglesIn = 0;  // over the meshes (each counted once)
  uint64_t verticesIn = 0, verticesOut = 0;
  double acmrIn = 0, acmrOut = 0;  // average cache miss ratio (16-entry FIFO), over all meshes
  size_t groupsMade = 0, levelsMade = 0;
  uint64_t levelTriangles = 0;  // in the generated levels
  std::string summary() const;
};

// Prepares `scene` in place. `progress` (optional) is called with the meshes done and the total.
// Errors: options out of range.
Result<PrepReport> prepare(scene::Scene& scene, const PrepOptions& options,
                           const std::function<void(size_t, size_t)>& progress = {});

}  // namespace sv::prep
