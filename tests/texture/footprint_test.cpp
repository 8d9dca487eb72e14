// The pixel footprint (SPEC §7 level of detail): the Jacobian ellipse against the pixel circle
// projected numerically onto a textured plane through exact ray–plane intersection, and the seed's
// planar formula against the same projection (exact at the centre, ≈ 20 % at the corners).
#include "texture/footprint.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>

namespace sv::texture {
namespace {

using V3 = std::array<double, 3>;
double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
V3 normalized(V3 a) {
  const double l = std::sqrt(dot(a, a));
  return {a[0] / l, a[1] / l, a[2] / l};
}
V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

// An eye at the origin looking down −z at an M × N screen with a 40°×30° view, and a textured
// plane N·P + d = 0 with unit texture axes in it, `texels` texels per unit length.
struct View {
  int M = 640, N = 480;
  double dx = 2.0 / 640 * std::tan(20 * M_PI / 180), dy = 2.0 / 480 * std::tan(15 * M_PI / 180);
  V3 normal, axisU, axisV, anchor;
  double d = 0, texels = 64;

  // The ray through screen position (sx, sy) (pixels, y down).
  V3 ray(double sx, double sy) const { return {(sx - M / 2.0) * dx, (N / 2.0 - sy) * dy, -1}; }
  // Texture coordinates in texels where that ray meets the plane.
  std::array<double, 2> uv(double sx, double sy) const {
    const V3 r = ray(sx, sy);
    const double t = -d / dot(normal, r);
    const V3 p = {t * r[0] - anchor[0], t * r[1] - anchor[1], t * r[2] - anchor[2]};
    return {texels * dot(p, axisU), texels * dot(p, axisV)};
  }
  // The widest diameter of the projected pixel circle (diameter 1 px, around the pixel centre).
  double projectedDiameter(int px, int py) const {
    double widest = 0;
    for (int i = 0; i < 180; ++i) {
      const double a = i * M_PI / 180;
      const auto p = uv(px + 0.5 + 0.5 * std::cos(a), py + 0.5 + 0.5 * std::sin(a));
      const auto q = uv(px + 0.5 - 0.5 * std::cos(a), py + 0.5 - 0.5 * std::sin(a));
      widest = std::max(widest, std::hypot(p[0] - q[0], p[1] - q[1]));
    }
    return widest;
  }
  // U, V, Q as linear functions of the pixel position (the header's symbols): with the ray linear
  // in (x, y), u = (−d·(r·U) − (P₀·U)(N·r)) / (N·r) in plane units; numerator and denominator are
  // negated so that Q > 0 in front of the eye, and u, v run over [0, 1] per unit length.
  void planes(int px, int py, LinearAt& U, LinearAt& V, LinearAt& Q) const {
    const V3 r = ray(px + 0.5, py + 0.5);
    const V3 rx = {dx, 0, 0}, ry = {0, -dy, 0};  // ∂r/∂x, ∂r/∂y
    auto numerator = [&](const V3& axis, const V3& v) {
      return d * dot(v, axis) + dot(anchor, axis) * dot(normal, v);
    };
    auto linear = [&](auto f) { return LinearAt{f(r), f(rx), f(ry)}; };
    U = linear([&](const V3& v) { return numerator(axisU, v); });
    V = linear([&](const V3& v) { return numerator(axisV, v); });
    Q = linear([&](const V3& v) { return -dot(normal, v); });
  }
};

View tiltedPlane(double tiltDegrees) {
  View v;
  // A ground-like plane tilted back by `tilt` from facing the eye, 5 units away along −z.
  const double t = tiltDegrees * M_PI / 180;
  v.normal = normalized({0, std::sin(t), std::cos(t)});
  v.anchor = {0, 0, -5};
  v.d = -dot(v.normal, v.anchor);
  v.axisU = normalized(cross({0, 1, 0}, v.normal));
  v.axisV = cross(v.normal, v.axisU);
  return v;
}

TEST(Footprint, JacobianEllipseMatchesTheProjectedPixelCircle) {
  for (double tilt : {0.0, 40.0, 70.0, 80.0})
    // Pixels at and below the centre row: the tilted plane's horizon cuts the upper screen.
    for (auto [px, py] : {std::array<int, 2>{320, 240}, {100, 400}, {600, 300}, {20, 470}}) {
      const View v = tiltedPlane(tilt);
      LinearAt U, V, Q;
      v.planes(px, py, U, V, Q);
      ASSERT_GT(Q.value, 0);
      const Footprint f = pixelFootprint(U, V, Q, v.texels, v.texels);
      const double numeric = v.projectedDiameter(px, py);
      EXPECT_NEAR(f.major, numeric, 0.02 * numeric)
          << "tilt " << tilt << " pixel " << px << "," << py;
      EXPECT_LE(f.minor, f.major);
      EXPECT_NEAR(f.lod, std::max(0.0, std::log2(f.major)), 1e-12);
      if (tilt >= 70) {
        EXPECT_GT(f.major, 1.5 * f.minor) << "grazing: a long, thin ellipse";
      }
    }
}

TEST(Footprint, MajorAxisPointsAlongTheStretch) {
  // Scale u by 4 and leave v: a pixel spans 4 times as many texels along u.
  const LinearAt U{0, 4, 0}, V{0, 0, 1}, Q{1, 0, 0};
  const Footprint f = pixelFootprint(U, V, Q, 1, 1);
  EXPECT_NEAR(f.major, 4, 1e-12);
  EXPECT_NEAR(f.minor, 1, 1e-12);
  EXPECT_NEAR(std::fabs(f.axisX), 1, 1e-12);
  EXPECT_NEAR(f.lod, 2, 1e-12);
  const Footprint g = pixelFootprint(LinearAt{0, 0.25, 0}, LinearAt{0, 0, 0.25}, Q, 1, 1);
  EXPECT_EQ(g.lod, 0);  // magnification: level 0
}

// SPEC §7: S is twice the projected width of one pixel; exact at the screen centre, and within the
// seed's stated ≈ 20 % towards the corners of a 40°×30° view.
TEST(Footprint, SeedFormulaAgreesAtTheCentreAndWithinItsStatedErrorElsewhere) {
  for (double tilt : {0.0, 30.0, 60.0}) {
    const View v = tiltedPlane(tilt);
    auto seed = [&](int px, int py) {
      const double x0 = px + 0.5 - v.M / 2.0, y0 = v.N / 2.0 - (py + 0.5);
      return 0.5 * v.texels *
             seedFootprint(v.normal[0], v.normal[1], v.normal[2], v.d, v.dx, v.dy, x0, y0);
    };
    const double centre = v.projectedDiameter(320, 240);
    EXPECT_NEAR(seed(320, 240), centre, 0.03 * centre) << tilt;
    for (auto [px, py] : {std::array<int, 2>{0, 0}, {639, 479}, {0, 479}, {639, 0}}) {
      const double numeric = v.projectedDiameter(px, py);
      EXPECT_NEAR(seed(px, py), numeric, 0.25 * numeric)
          << "tilt " << tilt << " corner " << px << "," << py;
    }
  }
}

}  // namespace
}  // namespace sv::texture
