// Matrix helpers. Based on: the OpenGL perspective and look-at conventions (glFrustum/gluLookAt).
#include "synthvis/math.h"

namespace sv {

Mat4 Mat4::translation(Vec3 t) {
  Mat4 r;
  r.m[3] = {t.x, t.y, t.z, 1};
  return r;
}

Mat4 Mat4::scaling(Vec3 s) {
  Mat4 r;
  r.m[0][0] = s.x;
  r.m[1][1] = s.y;
  r.m[2][2] = s.z;
  return r;
}

Mat4 Mat4::rotation(Vec3 axis, float radians) {
  Vec3 a = normalize(axis);
  float c = std::cos(radians), s = std::sin(radians), t = 1 - c;
  Mat4 r;
  r.m[0] = {t * a.x * a.x + c, t * a.x * a.y + s * a.z, t * a.x * a.z - s * a.y, 0};
  r.m[1] = {t * a.x * a.y - s * a.z, t * a.y * a.y + c, t * a.y * a.z + s * a.x, 0};
  r.m[2] = {t * a.x * a.z + s * a.y, t * a.y * a.z - s * a.x, t * a.z * a.z + c, 0};
  return r;
}

Mat4 Mat4::perspective(float yfov, float aspect, float znear, float zfar) {
  float f = 1.0f / std::tan(yfov / 2);
  Mat4 r;
  r.m[0] = {f / aspect, 0, 0, 0};
  r.m[1] = {0, f, 0, 0};
  r.m[2] = {0, 0, (zfar + znear) / (znear - zfar), -1};
  r.m[3] = {0, 0, 2 * zfar * znear / (znear - zfar), 0};
  return r;
}

// glFrustum's matrix: x_ndc = (2n·x/(r−l) + (r+l)/(r−l)·z)/(−z), so that x/(−z) = l/n maps to −1
// and r/n to +1 (likewise y with b, t). The depth row is `perspective`'s, written the same way so
// that a symmetric frustum gives the same depth bits.
Mat4 Mat4::frustum(float left, float right, float bottom, float top, float znear, float zfar) {
  Mat4 r;
  r.m[0] = {2 * znear / (right - left), 0, 0, 0};
  r.m[1] = {0, 2 * znear / (top - bottom), 0, 0};
  r.m[2] = {(right + left) / (right - left), (top + bottom) / (top - bottom),
            (zfar + znear) / (znear - zfar), -1};
  r.m[3] = {0, 0, 2 * zfar * znear / (znear - zfar), 0};
  return r;
}

Mat4 Mat4::lookAt(Vec3 eye, Vec3 target, Vec3 up) {
  Vec3 f = normalize(target - eye);
  Vec3 s = normalize(cross(f, up));
  if (length(s) == 0) s = normalize(cross(f, Vec3{1, 0, 0}));  // up parallel to view
  if (length(s) == 0) s = Vec3{1, 0, 0};
  Vec3 u = cross(s, f);
  Mat4 r;
  r.m[0] = {s.x, u.x, -f.x, 0};
  r.m[1] = {s.y, u.y, -f.y, 0};
  r.m[2] = {s.z, u.z, -f.z, 0};
  r.m[3] = {-dot(s, eye), -dot(u, eye), dot(f, eye), 1};
  return r;
}

Mat4 Mat4::fromColumnMajor(const float* v) {
  Mat4 r;
  for (int c = 0; c < 4; ++c)
    for (int row = 0; row < 4; ++row) r.m[c][row] = v[c * 4 + row];
  return r;
}

Mat4 operator*(const Mat4& a, const Mat4& b) {
  Mat4 r;
  for (int c = 0; c < 4; ++c)
    for (int row = 0; row < 4; ++row) {
      float s = 0;
      for (int k = 0; k < 4; ++k) s += a.m[k][row] * b.m[c][k];
      r.m[c][row] = s;
    }
  return r;
}

Vec3 Mat4::transformPoint(Vec3 p) const {
  Vec4 r = (*this) * Vec4{p.x, p.y, p.z, 1};
  return {r.x, r.y, r.z};
}

Vec3 Mat4::transformDirection(Vec3 d) const {
  Vec4 r = (*this) * Vec4{d.x, d.y, d.z, 0};
  return {r.x, r.y, r.z};
}

double linearDeterminant(const Mat4& m) {
  const auto& t = m.m;  // column-major: t[column][row]
  return double(t[0][0]) * (double(t[1][1]) * t[2][2] - double(t[2][1]) * t[1][2]) -
         double(t[1][0]) * (double(t[0][1]) * t[2][2] - double(t[2][1]) * t[0][2]) +
         double(t[2][0]) * (double(t[0][1]) * t[1][2] - double(t[1][1]) * t[0][2]);
}

bool affineInverse(const Mat4& m, double (&out)[3][4]) {
  double a[3][3];  // row r, column c
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) a[r][c] = m.m[c][r];
  const double det = linearDeterminant(m);
  if (!(std::fabs(det) > 1e-30) || !std::isfinite(det)) return false;
  const double id = 1 / det;
  const double inv[3][3] = {
      {(a[1][1] * a[2][2] - a[2][1] * a[1][2]) * id, (a[0][2] * a[2][1] - a[0][1] * a[2][2]) * id,
       (a[0][1] * a[1][2] - a[0][2] * a[1][1]) * id},
      {(a[1][2] * a[2][0] - a[1][0] * a[2][2]) * id, (a[0][0] * a[2][2] - a[0][2] * a[2][0]) * id,
       (a[1][0] * a[0][2] - a[0][0] * a[1][2]) * id},
      {(a[1][0] * a[2][1] - a[2][0] * a[1][1]) * id, (a[2][0] * a[0][1] - a[0][0] * a[2][1]) * id,
       (a[0][0] * a[1][1] - a[1][0] * a[0][1]) * id}};
  const double t[3] = {m.m[3][0], m.m[3][1], m.m[3][2]};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out[r][c] = inv[r][c];
    out[r][3] = -(inv[r][0] * t[0] + inv[r][1] * t[1] + inv[r][2] * t[2]);
  }
  return true;
}

Mat4 Mat4::normalMatrix() const {
  // The inverse transpose of the 3×3 part equals its cofactor matrix divided by its determinant.
  auto a = [this](int r, int c) { return m[c][r]; };
  float cof[3][3];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
      cof[r][c] = a(r1, c1) * a(r2, c2) - a(r1, c2) * a(r2, c1);
    }
  float det = a(0, 0) * cof[0][0] + a(0, 1) * cof[0][1] + a(0, 2) * cof[0][2];
  if (!(std::fabs(det) > 0) || !std::isfinite(det)) return Mat4{};
  Mat4 r;
  for (int row = 0; row < 3; ++row)
    for (int c = 0; c < 3; ++c) r.m[c][row] = cof[row][c] / det;
  return r;
}

}  // namespace sv
