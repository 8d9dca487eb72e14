// Appending one scene's records to another's (appendScene, and scene files that place other
// files): the database's own operation, shared with the readers.
#pragma once

#include <cstdint>

#include "synthvis/scene.h"

namespace sv::scene::detail {

// The switches, degrees of freedom, light points, lines and volumes of `other`, whose instances
// were appended to `scene` from index `instanceBase` on, placed by `transform`.
void appendArticulationsAndLights(Scene& scene, const Scene& other, const Mat4& transform,
                                  uint32_t instanceBase);

}  // namespace sv::scene::detail
