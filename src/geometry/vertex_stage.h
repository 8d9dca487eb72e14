// The vertex half of the projective transform (SPEC §1 stage 3): object space → clip space, with
// per-vertex Gouraud lighting (SPEC §8) and the attributes pixel shading interpolates.
#pragma once

#include <span>

#include "geometry/attributes.h"
#include "geometry/setup.h"
#include "synthvis/math.h"

namespace sv::geometry {

// A mesh's vertex arrays as the vertex stage reads them (render passes a scene::Mesh's): `count`
// positions and, per vertex, the optional normals, RGBA colours and texture coordinates (nullptr:
// none).
struct VertexArrays {
  const Vec3* positions = nullptr;
  size_t count = 0;
  const Vec3* normals = nullptr;
  const Vec4* colors = nullptr;
  const Vec2* uvs = nullptr;
};

// What the vertex stage reads of a material.
struct VertexMaterial {
  Vec4 baseColor{1, 1, 1, 1};  // linear RGBA, multiplies vertex colours
  Vec2 uvScale{1, 1};          // multiplies the texture coordinates
  bool unlit = false;          // the lights are ignored
  bool phong = false;          // lit per pixel: the vertex colour is left unlit
};

// The lights of the frame, in world space (SPEC §8).
struct DirectionalLight {
  Vec3 direction{-0.4f, -1.0f, -0.6f};  // the direction the light travels (scene::Light's default)
  Vec3 color{1, 1, 1};
  float ambient = 0.25f;
  bool enabled = true;
};
struct PointLight {
  Vec3 position{0, 0, 0};
  Vec3 color{1, 1, 1};
};

// What the vertex stage needs of the frame: camera and lights.
struct VertexContext {
  Mat4 view;      // world → eye
  Mat4 viewProj;  // projection·view
  DirectionalLight light;
  std::span<const PointLight> pointLights;
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
bool transformVertices(const VertexArrays& mesh, const VertexMaterial& material, const Mat4& model,
                       const VertexContext& context, size_t begin, size_t end, ClipVertex* out,
                       float* attributes = nullptr, const AttributeLayout* layout = nullptr);

// The bound of an object whose vertices lie in the box [lo, hi] placed by `mvp` (object → clip):
// the projected corners' pixel box, widened by two pixels for vertex rounding and sample
// apertures, and their nearest window depth less a margin for the depth planes' float rounding.
// False when no bound exists: the box reaches behind the near plane (its projection is then
// unbounded, SPEC §2), or it is not finite.
bool boundObject(const Mat4& mvp, Vec3 lo, Vec3 hi, const Viewport& viewport, ObjectBound& out);

}  // namespace sv::geometry
