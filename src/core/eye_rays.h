// The rays of a view through raster points, and depth along them, for the passes that cast rays
// from the eye (terrain, volumes): a point at depth s on the ray through raster point (px, py) is
// eye + s·direction(px, py), and s ↔ the depth buffer's window depth by the projection's depth
// row. A view is a window (a pinhole camera's, s its eye depth) or — distortion correction's
// sub-frusta (SPEC §12) — any projective map of the rays onto the raster (s the depth along the
// map's axis, the projection's w).
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/projective.h"
#include "core/quadric.h"
#include "synthvis/math.h"

namespace sv {

// A projection's depth row as a function of its w (which is eye depth for glFrustum's, the depth
// along the cell's axis for a sub-frustum cell's): z = a·w + b, so ndc z = −p22 + p23/w with
// p22 = −a and p23 = b. For glFrustum's (w = −z_eye) p22 is its m[2][2], exactly.
inline double depthP22(const Mat4& projection) {
  double zw = 0, ww = 0;
  for (size_t k = 0; k < 3; ++k) {
    zw += double(projection.m[k][2]) * double(projection.m[k][3]);
    ww += double(projection.m[k][3]) * double(projection.m[k][3]);
  }
  return -zw / ww;
}

struct EyeRays {
  // The camera in the world: eye and the eye space's axes (forward = −z).
  Vec3d eye, forward, right, up;
  // The view window at unit depth: its centre and half-size (a channel's may be asymmetric, SPEC
  // §9). A centre of 0 is stored as −0, which adds to any value without changing a bit, so the
  // classic symmetric view casts exactly the rays it always did.
  double halfX = 1, halfY = 1, centreX = -0.0, centreY = -0.0;
  // A projective view (ofProjection): the ray through NDC point (x, y) is ndc0 + x·ndcX + y·ndcY,
  // its component along `axis` 1. A window's rays are the camera's frame above, `axis` forward.
  bool projective = false;
  Vec3d ndc0, ndcX, ndcY, axis;
  double znear = 0.1, zfar = 1000;
  double p22 = 0, p23 = 0;    // the projection's depth row: ndc z = −p22 + p23/s
  int width = 1, height = 1;  // the raster

  // `view` world → eye, `projection` its GL projection, the window's tangents at unit depth (left,
  // right, bottom, top), the near and far planes, and the raster's size.
  static EyeRays of(const Mat4& view, const Mat4& projection, double tanLeft, double tanRight,
                    double tanBottom, double tanTop, double znear, double zfar) {
    EyeRays r;
    const auto& v = view.m;
    r.right = {v[0][0], v[1][0], v[2][0]};
    r.up = {v[0][1], v[1][1], v[2][1]};
    const Vec3d back{v[0][2], v[1][2], v[2][2]};
    r.forward = back * -1.0;
    r.eye = (r.right * v[3][0] + r.up * v[3][1] + back * v[3][2]) * -1.0;
    r.halfX = 0.5 * (tanRight - tanLeft);
    r.halfY = 0.5 * (tanTop - tanBottom);
    r.centreX = 0.5 * (tanRight + tanLeft);
    r.centreY = 0.5 * (tanTop + tanBottom);
    if (r.centreX == 0) r.centreX = -0.0;
    if (r.centreY == 0) r.centreY = -0.0;
    r.znear = znear;
    r.zfar = zfar;
    r.p22 = projection.m[2][2];
    r.p23 = projection.m[3][2];
    r.axis = r.forward;
    return r;
  }
  // A view through `projection`, any map of eye space whose x, y and w rows are linear in the
  // direction from the eye (no translation: the eye is the centre of projection) and whose depth
  // row is glFrustum's with w for depth (z = a·w + b) — a sub-frustum cell's (display/subfrustum.h).
  // `eye`, `right`, `up` and `forward` stay the view's own frame (for shading); depth is along the
  // projection's w. Nothing for a projection whose rows are singular.
  static std::optional<EyeRays> ofProjection(const Mat4& view, const Mat4& projection, double znear,
                                             double zfar) {
    EyeRays r = of(view, projection, -1, 1, -1, 1, znear, zfar);
    // Q: the x, y and w rows on eye-space directions (Mat4 is column-major: m[column][row]).
    Mat3d q;
    const size_t rows[3] = {0, 1, 3};
    for (size_t i = 0; i < 3; ++i)
      for (size_t k = 0; k < 3; ++k) q.m[i][k] = projection.m[k][rows[i]];
    const std::optional<Mat3d> inverse = q.inverse();
    if (!inverse) return std::nullopt;
    // The eye-space direction Q⁻¹·(x, y, 1) (its w is 1), taken to the world by the view's axes.
    const auto toWorld = [&r](double ex, double ey, double ez) {
      return r.right * ex + r.up * ey + r.forward * -ez;
    };
    const auto& m = inverse->m;
    r.ndcX = toWorld(m[0][0], m[1][0], m[2][0]);
    r.ndcY = toWorld(m[0][1], m[1][1], m[2][1]);
    r.ndc0 = toWorld(m[0][2], m[1][2], m[2][2]);
    r.axis = toWorld(q.m[2][0], q.m[2][1], q.m[2][2]);
    r.p22 = depthP22(projection);
    r.p23 = projection.m[3][2];
    r.projective = true;
    return r;
  }

  // The ray through raster point (px, py), its component along `axis` 1 (s is depth): the sum
  // (base + column(px)) + row(py), which a pass that casts many rays of a column or row may
  // evaluate from the terms it keeps, to the same bits.
  Vec3d direction(double px, double py) const { return (base() + column(px)) + row(py); }
  Vec3d base() const { return projective ? ndc0 : forward; }
  Vec3d column(double px) const {
    return projective ? ndcX * (2 * px / width - 1)
                      : right * ((2 * px / width - 1) * halfX + centreX);
  }
  Vec3d row(double py) const {
    return projective ? ndcY * (1 - 2 * py / height)
                      : up * ((1 - 2 * py / height) * halfY + centreY);
  }
  // Half the view's height in direction per unit depth (at its centre, for a projective view): a
  // pixel spans 2·halfSpanY()/height there.
  double halfSpanY() const { return projective ? std::sqrt(dot(ndcY, ndcY)) : halfY; }
  // Window depth (z + 1)/2 ↔ eye depth s: ndc z = −p22 + p23/s (the GL projection's depth row).
  double depthToS(float depth) const {
    if (!(depth < 1.0f)) return zfar;
    const double ndc = 2.0 * depth - 1.0;
    return std::clamp(p23 / (ndc + p22), znear, zfar);
  }
  float sToDepth(double s) const { return float(0.5 * (-p22 + p23 / s) + 0.5); }
};

}  // namespace sv
