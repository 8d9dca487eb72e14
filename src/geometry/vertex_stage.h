// The vertex half of the projective transform (SPEC §1 stage 3): object space → clip space, with
// per-vertex Gouraud lighting (SPEC §8) and the attributes pixel shading interpolates.
#pragma once

#include <vector>

#include "geometry/setup.h"
#include "geometry/attributes.h"
#include "synthvis/scene.h"

namespace sv::geometry {

// What the vertex stage needs of the frame: camera and lights.
struct VertexContext {
  Mat4 view;      // world → eye
  Mat4 viewProj;  // projection·view
  const scene::Light* light = nullptr;
  const std::vector<scene::PointLight>* pointLights = nullptr;  // world space
};

// Writes the clip-space vertices of mesh vertices [begin, end) to out[0 … end − begin), and, when
// `attributes` is not null, their pixel-shading attributes (Attribute: uv, eye-space normal
// and position, alpha) that `layout` stores, vertex i's at attributes[i·layout.stride + slot].
// `model` places the mesh in the world. Colour = material colour × vertex colour × light intensity,
// where intensity = ambient + (1 − ambient)·Σ max(0, n·l)·lightColour over the directional light
// and the point lights when the mesh has normals, the light is enabled and the material is lit
// and not Phong (Phong materials are lit per pixel: their colour is left unlit); back faces of
// double-sided materials are lit as seen from the front (the vertex stage cannot know facing),
// which matches common viewers.
// Returns whether every position read was finite (scene::validate's check, made here where the
// positions are read anyway: the renderer skips it in validate).
bool transformVertices(const scene::Mesh& mesh, const scene::Material& material, const Mat4& model,
                       const VertexContext& context, size_t begin, size_t end, ClipVertex* out,
                       float* attributes = nullptr, const AttributeLayout* layout = nullptr);

// The bound of an object whose vertices lie in the box [lo, hi] placed by `mvp` (object → clip):
// the projected corners' pixel box, widened by two pixels for vertex rounding and sample
// apertures, and their nearest window depth less a margin for the depth planes' float rounding.
// False when no bound exists: the box reaches behind the near plane (its projection is then
// unbounded, SPEC §2), or it is not finite.
bool boundObject(const Mat4& mvp, Vec3 lo, Vec3 hi, const Viewport& viewport, ObjectBound& out);

}  // namespace sv::geometry
