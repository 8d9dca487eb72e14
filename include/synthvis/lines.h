// Lines (the line pass, src/lines): plain records (public API), shared by the scene (which holds
// them) and the pass (which draws them); docs/scene-format.md, "Lines", says how they are drawn.
#pragma once

#include <cstddef>

#include "synthvis/math.h"

namespace sv::scene {

// A line of the scene (a glTF line primitive, an OBJ `l` element, an OpenFlight wireframe face, a
// scene file's polyline): a segment in world space, drawn by the line pass (src/lines) as a strip
// `LineSettings::width` pixels wide facing the eye, sampled like a polygon by the frame's sample
// pattern, depth-tested and fogged like a surface, in its own colour (lines are not lit).
struct LineSegment {
  Vec3 a, b;            // world
  Vec3 color{1, 1, 1};  // linear
};

// Most line segments one scene may hold (loaders refuse more).
inline constexpr size_t kMaxLines = size_t(1) << 22;

// How lines become pixels (docs/scene-format.md, "Lines").
struct LineSettings {
  float width = 1;  // pixels, 1/64 … 64: the strip's width, whatever the line's distance
  // A line is drawn as if this fraction of its distance nearer the eye, so that a line lying on a
  // surface (a wireframe over its faces, a runway's centre line) shows over it without breaking up.
  float depthBias = 1.0f / 1024;
};

}  // namespace sv::scene
