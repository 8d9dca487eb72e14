// What shading needs at a free form's hits — the object-space point, the gradient there, the
// outward unit normal and the position in eye space — for up to 16 hits at a time, every hit a
// SIMD lane (Highway, per target; surface_points.cpp).
//
// Based on: SPEC §12 (seed 003: at a leaf, the surface point and the normal from the gradient).
#pragma once

#include "freeform/freeform.h"

namespace sv::freeform {

struct SurfaceLanes {
  alignas(64) double point[3][16];     // object space
  alignas(64) double gradient[3][16];  // FreeForm::gradient at the point
  alignas(64) double normal[3][16];    // eye space, unit, outward (−∇F carried by normalToEye)
  alignas(64) double eye[3][16];       // eye space
  // As shading reads them, in the order of shade::Attribute from kU, so that they are copied into
  // shade::Fragments::attribute whole: float(point.x·uScale), float(point.z·vScale) — the
  // texture projected along the object's y axis — then the normal and the eye position, each
  // rounded to float.
  static constexpr int kU = 0, kV = 1, kNormal = 2, kEye = 5, kFloats = 8;
  alignas(64) float floats[kFloats][16];
};

class SurfacePoints {
 public:
  // `form` in object space; `cubeToObject` the map of the cube (ProjectedFreeForm::inverse);
  // `objectToEye` and its inverse transpose `normalToEye` (3×3 part) carry points and normals.
  // `uScale`, `vScale`: the texture coordinates' scales (SurfaceLanes::u, v).
  SurfacePoints(const FreeForm& form, const Mat4d& cubeToObject, const Mat4d& objectToEye,
                const Mat4d& normalToEye, double uScale = 1, double vScale = 1);

  // The hits at cube points (x[i], y[i], z[i]), i < count ≤ 16. Each lane performs the double
  // operations of Mat4d::transformPoint, FreeForm::gradient and normalize in the same order, so
  // the values are theirs bit for bit, on every target (tests/freeform).
  // `active`: the root's perturbations that may be positive at these points (castWindow's); the
  // others, 0 there, are left out. `floats` (if given): where SurfaceLanes::floats go instead —
  // straight into shading's fragments (shade::Fragments::attribute from kU).
  void at(const double* x, const double* y, const double* z, int count, SurfaceLanes& out,
          uint64_t active = kAllActive, float (*floats)[16] = nullptr) const;

 private:
  ProjectedFreeForm object_;  // the form flattened, in object space (the identity map)
  Mat4d cubeToObject_, objectToEye_, normalToEye_;
  double uScale_, vScale_;
};

}  // namespace sv::freeform
