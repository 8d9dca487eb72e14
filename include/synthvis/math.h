// Small vector and matrix types shared by every stage.
//
// Conventions: right-handed world, camera looks down −Z (as glTF and OpenGL), matrices are
// column-major (m[col][row], as glTF stores them) and act on column vectors: p' = M·p.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace sv {

struct Vec2 {
  float x = 0, y = 0;
  friend bool operator==(Vec2 a, Vec2 b) = default;
};

struct Vec3 {
  float x = 0, y = 0, z = 0;
  friend Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  friend Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  friend Vec3 operator*(Vec3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
  friend Vec3 operator*(float s, Vec3 a) { return a * s; }
  friend Vec3 operator*(Vec3 a, Vec3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
  friend Vec3 operator-(Vec3 a) { return {-a.x, -a.y, -a.z}; }
  friend bool operator==(Vec3 a, Vec3 b) = default;
};

struct Vec4 {
  float x = 0, y = 0, z = 0, w = 0;
  friend bool operator==(Vec4 a, Vec4 b) = default;
};

inline float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length(Vec3 a) { return std::sqrt(dot(a, a)); }
// Every component finite (false for NaN and ±∞). Branch-free, so that a reduction over many
// positions vectorizes (scene::validate, the vertex stage).
inline bool isFinite(Vec3 a) {
  constexpr float kMax = std::numeric_limits<float>::max();
  return (std::fabs(a.x) <= kMax) & (std::fabs(a.y) <= kMax) & (std::fabs(a.z) <= kMax);
}
// Returns `a` scaled to unit length, or `a` unchanged when it is zero or not finite.
inline Vec3 normalize(Vec3 a) {
  constexpr float kMin = std::numeric_limits<float>::min(),
                  kMax = std::numeric_limits<float>::max();
  const float d = dot(a, a);
  if (d >= kMin && d <= kMax) return a * (1.0f / std::sqrt(d));
  // The squared length overflowed (components beyond ~1e19) or fell below float's normal range
  // (below ~1e-19, where it loses bits and 1 / length can overflow): divided by its largest
  // component first, the vector has a length in [1, √3].
  if (!isFinite(a)) return a;
  const float m = std::max(std::fabs(a.x), std::max(std::fabs(a.y), std::fabs(a.z)));
  if (m == 0) return a;
  const Vec3 b{a.x / m, a.y / m, a.z / m};
  return b * (1.0f / length(b));
}

// Vec3 in double: the one double vector type — for the free forms' and the terrain's rays, the
// display's directions and the host's geodetic positions, where float loses what they need.
struct Vec3d {
  double x = 0, y = 0, z = 0;
  friend Vec3d operator+(Vec3d a, Vec3d b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  friend Vec3d operator-(Vec3d a, Vec3d b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  friend Vec3d operator*(Vec3d a, double s) { return {a.x * s, a.y * s, a.z * s}; }
  friend Vec3d operator*(double s, Vec3d a) { return a * s; }
};
inline double dot(Vec3d a, Vec3d b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3d cross(Vec3d a, Vec3d b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double length(Vec3d v) { return std::sqrt(dot(v, v)); }
// `v` scaled to unit length, or unchanged when it has zero length.
inline Vec3d normalize(Vec3d v) {
  const double l = std::sqrt(dot(v, v));
  return l > 0 ? v * (1 / l) : v;
}
// The angle between a and b, radians: atan2(|a × b|, a · b), accurate at small angles, where acos
// of the dot product is not.
inline double angleBetween(Vec3d a, Vec3d b) {
  const Vec3d c = cross(a, b);
  return std::atan2(std::sqrt(dot(c, c)), dot(a, b));
}
inline Vec3 toFloat(Vec3d v) { return {float(v.x), float(v.y), float(v.z)}; }
inline Vec3d toDouble(Vec3 v) { return {v.x, v.y, v.z}; }

// 4×4 matrix, column-major: m[c][r] is row r of column c.
struct Mat4 {
  std::array<std::array<float, 4>, 4> m{{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};

  static Mat4 identity() { return {}; }
  static Mat4 translation(Vec3 t);
  static Mat4 scaling(Vec3 s);
  // Rotation by `radians` about the unit `axis` (right-handed).
  static Mat4 rotation(Vec3 axis, float radians);
  // OpenGL-style perspective projection: vertical field of view in radians, clip z ∈ [−w, w].
  static Mat4 perspective(float yfov, float aspect, float znear, float zfar);
  // OpenGL-style (glFrustum) off-axis projection: the view window's left, right, bottom and top
  // edges on the near plane z = −znear (left < right, bottom < top; asymmetric allowed), clip
  // z ∈ [−w, w] with the same depth row as `perspective`. SPEC §9: a display channel's frustum.
  static Mat4 frustum(float left, float right, float bottom, float top, float znear, float zfar);
  // View matrix of a camera at `eye` looking at `target`.
  static Mat4 lookAt(Vec3 eye, Vec3 target, Vec3 up);
  // Column-major 16 floats, as glTF and the JSON scene format store them.
  static Mat4 fromColumnMajor(const float* v);

  friend Mat4 operator*(const Mat4& a, const Mat4& b);
  Vec4 operator*(Vec4 v) const {
    return {m[0][0] * v.x + m[1][0] * v.y + m[2][0] * v.z + m[3][0] * v.w,
            m[0][1] * v.x + m[1][1] * v.y + m[2][1] * v.z + m[3][1] * v.w,
            m[0][2] * v.x + m[1][2] * v.y + m[2][2] * v.z + m[3][2] * v.w,
            m[0][3] * v.x + m[1][3] * v.y + m[2][3] * v.z + m[3][3] * v.w};
  }
  Vec3 transformPoint(Vec3 p) const;      // w = 1, no divide
  Vec3 transformDirection(Vec3 d) const;  // w = 0
  // The inverse transpose of the upper 3×3, for normals. Returns identity when singular.
  Mat4 normalMatrix() const;
  friend bool operator==(const Mat4& a, const Mat4& b) = default;
};

// The determinant of m's upper 3×3 (an affine transform's linear part), in double.
double linearDeterminant(const Mat4& m);
// The inverse of an affine m (last row 0, 0, 0, 1) in double, as rows r = 0…2 of the inverse's
// upper 3 × 4: [inverse of the upper 3×3 (its cofactors times 1/det) | −that · m's translation].
// False, `out` untouched, when the upper 3×3 is singular (|det| ≤ 1e-30) or not finite.
bool affineInverse(const Mat4& m, double (&out)[3][4]);

inline bool isFinite(const Mat4& m) {
  for (const auto& column : m.m)
    for (float x : column)
      if (!std::isfinite(x)) return false;
  return true;
}

}  // namespace sv
