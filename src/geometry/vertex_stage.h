// The vertex half of the projective transform (SPEC §1 stage 3): object space → clip space, with
// per-vertex Gouraud lighting (SPEC §8).
#pragma once

#include <vector>

#include "geometry/setup.h"
#include "synthvis/scene.h"

namespace sv::geometry {

// Writes the clip-space vertices of mesh vertices [begin, end) to out[0 … end − begin).
// `model` places the mesh in the world,
// `viewProj` is projection·view. Colour = material colour × vertex colour × light intensity, where
// intensity = ambient + (1 − ambient)·max(0, n·l)·lightColour when the mesh has normals, the light
// is enabled and the material is lit; back faces of double-sided materials are lit as seen from
// the front (the vertex stage cannot know facing), which matches common viewers.
void transformVertices(const scene::Mesh& mesh, const scene::Material& material, const Mat4& model,
                       const Mat4& viewProj, const scene::Light& light, size_t begin, size_t end,
                       ClipVertex* out);

}  // namespace sv::geometry
