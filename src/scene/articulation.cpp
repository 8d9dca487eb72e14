// Articulations (scene.h Switch, Dof): the host's switch masks and degree-of-freedom motions
// turned into instance visibility and transforms.
// Based on: SPEC §1 (the traversal draws what the database's state selects); OpenFlight 16.x's
// switch (mask per child) and DOF (local frame, translate · rotate · scale) records.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "synthvis/scene.h"

namespace sv::scene {

Mat4 dofMatrix(const DofMotion& m) {
  constexpr float kRad = std::numbers::pi_v<float> / 180.0f;
  // Yaw first, then roll, then pitch: the order OpenSceneGraph's OpenFlight reader gives (and
  // the tests hold us to it).
  const Mat4 r = Mat4::rotation({1, 0, 0}, m.rotate.x * kRad) *
                 Mat4::rotation({0, 1, 0}, m.rotate.y * kRad) *
                 Mat4::rotation({0, 0, 1}, m.rotate.z * kRad);
  return Mat4::translation(m.translate) * r * Mat4::scaling(m.scale);
}

namespace {

// The inverse of a rigid transform: the transposed rotation, the origin moved back.
Mat4 rigidInverse(const Mat4& f) {
  Mat4 r;
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 3; ++k) r.m[c][k] = f.m[k][c];
  const Vec3 t{f.m[3][0], f.m[3][1], f.m[3][2]};
  for (int k = 0; k < 3; ++k) r.m[3][k] = -(r.m[0][k] * t.x + r.m[1][k] * t.y + r.m[2][k] * t.z);
  return r;
}

Vec3 clampVec(Vec3 v, Vec3 lo, Vec3 hi) {
  return {std::clamp(v.x, lo.x, std::max(lo.x, hi.x)), std::clamp(v.y, lo.y, std::max(lo.y, hi.y)),
          std::clamp(v.z, lo.z, std::max(lo.z, hi.z))};
}

}  // namespace

void applyArticulations(Scene& scene) {
  // Switches: an instance is drawn where every switch above it draws its child.
  for (const Switch& s : scene.switches)
    for (const std::vector<uint32_t>& child : s.children)
      for (uint32_t i : child)
        if (i < scene.instances.size()) scene.instances[i].visible = true;
  for (const Switch& s : scene.switches) {
    if (s.masks.empty()) continue;
    const std::vector<bool>& mask = s.masks[std::min(s.current, s.masks.size() - 1)];
    for (size_t c = 0; c < s.children.size(); ++c)
      if (c >= mask.size() || !mask[c])
        for (uint32_t i : s.children[c])
          if (i < scene.instances.size()) scene.instances[i].visible = false;
  }
  // Degrees of freedom, parents before children (a parent has the smaller index).
  std::vector<Mat4> moved(scene.dofs.size());
  for (size_t d = 0; d < scene.dofs.size(); ++d) {
    const Dof& dof = scene.dofs[d];
    DofMotion m = dof.current;
    m.translate = clampVec(m.translate, dof.min.translate, dof.max.translate);
    m.rotate = clampVec(m.rotate, dof.min.rotate, dof.max.rotate);
    m.scale = clampVec(m.scale, dof.min.scale, dof.max.scale);
    const Mat4 above = dof.parent >= 0 && size_t(dof.parent) < d ? moved[size_t(dof.parent)]
                                                                  : Mat4::identity();
    moved[d] = above * dof.place * dof.frame * dofMatrix(m) * rigidInverse(dof.frame);
    for (const auto& [i, part] : dof.parts)
      if (i < scene.instances.size()) scene.instances[i].transform = moved[d] * part;
  }
}

}  // namespace sv::scene
