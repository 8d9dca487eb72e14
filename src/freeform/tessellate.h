// Free forms as triangles: the polygon baseline issue 7 measures ray casting against (and what
// lets the OpenGL reference draw a free-form scene at all).
//
// Based on: marching tetrahedra (Doi & Koide 1991) on the leaves of an interval octree
// (the bounds of freeform.h decide which cells can hold the surface); vertices placed on the
// surface by bisection along the cell edge, normals from the gradient.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <vector>

#include "freeform/freeform.h"

namespace sv::freeform {

using Box = std::array<Vec3d, 2>;  // lo, hi

// The box of the octree cells (of side 2·extent / 2^levels, from the cube ±extent) whose bounds
// may hold the surface; nothing when none does. `unbounded` is set (and nothing returned) when the
// surface reaches the cube's faces or the search would visit over 2^22 cells.
std::optional<Box> surfaceBounds(const FreeForm& form, double extent, int levels, bool& unbounded);

// Triangles, three vertices each, counter-clockwise seen from outside (F' < 0), with unit
// outward normals per vertex.
struct TriangleSoup {
  std::vector<Vec3d> positions;
  std::vector<Vec3d> normals;
  size_t triangles() const { return positions.size() / 3; }
};

// Appends to `out` the surface of `form` inside `box`, from octree leaves of side ≤ `cell`. False
// (with `out` partly filled) once `out` would exceed `maxTriangles`.
bool tessellate(const FreeForm& form, const Box& box, double cell, size_t maxTriangles,
                TriangleSoup& out);

}  // namespace sv::freeform
