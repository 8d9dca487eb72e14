// The rays of a view through raster points, and depth along them, for the passes that cast rays
// from the eye (terrain, volumes): a point at eye depth s on the ray through raster point (px, py)
// is eye + s·direction(px, py), and s ↔ the depth buffer's window depth by the projection's depth
// row.
#pragma once

#include <algorithm>

#include "core/quadric.h"
#include "synthvis/math.h"

namespace sv {

struct EyeRays {
  // The camera in the world: eye and the eye space's axes (forward = −z).
  Vec3d eye, forward, right, up;
  // The view window at unit depth: its centre and half-size (a channel's may be asymmetric, SPEC
  // §9). A centre of 0 is stored as −0, which adds to any value without changing a bit, so the
  // classic symmetric view casts exactly the rays it always did.
  double halfX = 1, halfY = 1, centreX = -0.0, centreY = -0.0;
  double znear = 0.1, zfar = 1000;
  double p22 = 0, p23 = 0;  // the projection's depth row: ndc z = −p22 + p23/s
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
    return r;
  }

  // The ray through raster point (px, py), its forward component 1 (s is eye depth).
  Vec3d direction(double px, double py) const {
    return forward + right * ((2 * px / width - 1) * halfX + centreX) +
           up * ((1 - 2 * py / height) * halfY + centreY);
  }
  // Window depth (z + 1)/2 ↔ eye depth s: ndc z = −p22 + p23/s (the GL projection's depth row).
  double depthToS(float depth) const {
    if (!(depth < 1.0f)) return zfar;
    const double ndc = 2.0 * depth - 1.0;
    return std::clamp(p23 / (ndc + p22), znear, zfar);
  }
  float sToDepth(double s) const { return float(0.5 * (-p22 + p23 / s) + 0.5); }
};

}  // namespace sv
