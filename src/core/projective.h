// Projective maps fixed by point pairs: the five-point map of 3-space (SPEC §12) and its analogue
// in the plane, the four-point homography. Core maths, because distortion correction
// (display/subfrustum.h), the free forms' frustum-to-cube map (core/quadric.h) and the tests all
// need them.
//
// Based on: SPEC §12 (seed 003): "A projective map of 3-space is fixed by five pairs of
// corresponding points, no four of the five coplanar: solve (C)(M^i) = r_i (P^i) for i = 1…5,
// with r_5 = 1." The construction is the classical one through the projective frame (e.g.
// Hartley & Zisserman, Multiple View Geometry, 2nd ed., §2.3 and §4.1 for the plane): the N + 1
// points of a frame in general position are the images of e_1 … e_N and e_1 + … + e_N.
//
// Points are homogeneous: (x, y, z, w) in space, (x, y, w) in the plane — a point at infinity is
// as good as any. Symbols keep the SPEC's: C the map, M^i the source points, P^i the targets,
// r_i the scale each target is reached with.
#pragma once

#include <array>
#include <optional>

#include "core/quadric.h"  // Vec3d, Vec4d, Mat4d
#include "synthvis/result.h"

namespace sv {

// A 3×3 matrix in double, row-major (m[r][c]), acting on column vectors: a homography of the
// plane on homogeneous (x, y, w).
struct Mat3d {
  std::array<std::array<double, 3>, 3> m{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  friend Mat3d operator*(const Mat3d& a, const Mat3d& b);
  Vec3d operator*(Vec3d v) const {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
            m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
  }
  // Nothing when singular (as Mat4d::inverse, of which it is the upper block).
  std::optional<Mat3d> inverse() const;
};

// How independent a set of points must be: the normalized determinant |det(p_1 … p_N)| /
// (|p_1| ⋯ |p_N|) of every N of the N + 1 points (Hadamard's ratio: 1 for orthogonal vectors, 0 for
// dependent ones, i.e. four coplanar points in space or three collinear in the plane) must exceed
// it. Below 1e-12 the solve's condition number passes 10^12 and a map's entries keep fewer than
// four significant digits in double.
inline constexpr double kMinPointIndependence = 1e-12;

// SPEC §12: the map C of 3-space with C·M^i = r_i·P^i for i = 1 … 5, r_5 = 1 (so C·M^5 = P^5
// exactly, scale included), M[i − 1] = M^i. Refuses, naming the four points, a set where four of
// the five sources or of the five targets are coplanar (their normalized determinant at most
// kMinPointIndependence), and any point that is zero or not finite.
Result<Mat4d> solveProjectiveMap(const std::array<Vec4d, 5>& M, const std::array<Vec4d, 5>& P);

// The plane's analogue: the homography H with H·M^i = r_i·P^i for i = 1 … 4, r_4 = 1, on
// homogeneous points (x, y, w). Refuses a set with three collinear points (three of the four
// sources or targets), or a zero or non-finite point.
Result<Mat3d> solveHomography(const std::array<Vec3d, 4>& M, const std::array<Vec3d, 4>& P);

}  // namespace sv
