// Display geometry: projector rays against a cylinder or sphere, seen from the eye.
// Based on: SPEC §12 (distortion correction: a table of unit vectors per display, recomputed when
// the eye or projector moves); issue 34 item 1. The ray–quadric intersections are the textbook
// quadratic (e.g. Pharr, Jakob & Humphreys, PBRT 4th ed., §6.2 for spheres, §6.3 for cylinders),
// solved in double with the cancellation-free form of the roots.
#include "display/geometry.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/quadric.h"

namespace sv::display {
namespace {

constexpr double kToRadians = std::numbers::pi / 180;
constexpr double kToDegrees = 180 / std::numbers::pi;

// Row-major 3×3 products.
Rotation multiply(const Rotation& a, const Rotation& b) {
  Rotation r{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      r.m[i][j] = a.m[i][0] * b.m[0][j] + a.m[i][1] * b.m[1][j] + a.m[i][2] * b.m[2][j];
  return r;
}
// Right-handed turns about +x, +y, +z.
Rotation aboutX(double a) {
  const double c = std::cos(a), s = std::sin(a);
  return {{{1, 0, 0}, {0, c, -s}, {0, s, c}}};
}
Rotation aboutY(double a) {
  const double c = std::cos(a), s = std::sin(a);
  return {{{c, 0, s}, {0, 1, 0}, {-s, 0, c}}};
}
Rotation aboutZ(double a) {
  const double c = std::cos(a), s = std::sin(a);
  return {{{c, -s, 0}, {s, c, 0}, {0, 0, 1}}};
}

// The smallest t > 0 at which o + t·d lies on the screen's surface and within its extent, or a
// negative number. Roots of a·t² + b·t + c = 0 by q = −(b + sign(b)·√disc)/2, t = q/a and c/q,
// which avoids the cancellation of the schoolbook formula when b² ≫ 4ac.
double hitScreen(const Screen& s, Vec3d o, Vec3d d) {
  const Vec3d rel{o.x - s.centre.x, o.y - s.centre.y, o.z - s.centre.z};
  const bool sphere = s.shape == ScreenShape::sphere;
  const double a = d.x * d.x + d.z * d.z + (sphere ? d.y * d.y : 0);
  const double b = 2 * (rel.x * d.x + rel.z * d.z + (sphere ? rel.y * d.y : 0));
  const double c = rel.x * rel.x + rel.z * rel.z + (sphere ? rel.y * rel.y : 0) - s.radius * s.radius;
  if (!(a > 1e-300)) return -1;  // a vertical ray never meets the cylinder's wall
  const double disc = b * b - 4 * a * c;
  if (!(disc >= 0)) return -1;
  const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
  double t0 = q / a, t1 = q != 0 ? c / q : t0;
  if (t0 > t1) std::swap(t0, t1);
  for (double t : {t0, t1}) {
    if (!(t > 1e-9)) continue;
    const Vec3d p{rel.x + t * d.x, rel.y + t * d.y, rel.z + t * d.z};
    const double azimuth = std::atan2(p.x, -p.z) * kToDegrees;
    if (azimuth < s.minAzimuthDegrees || azimuth > s.maxAzimuthDegrees) continue;
    if (sphere) {
      const double elevation = std::atan2(p.y, std::hypot(p.x, p.z)) * kToDegrees;
      if (elevation < s.minElevationDegrees || elevation > s.maxElevationDegrees) continue;
    } else if (p.y < s.minHeight || p.y > s.maxHeight) {
      continue;
    }
    return t;
  }
  return -1;
}

// What every ray of a projector shares: its lens's tangents and its rotation (six trigonometric
// calls, made once per table rather than once per pixel).
struct ProjectorFrame {
  WindowTangents t;
  Rotation r;
};
ProjectorFrame frameOf(const Projector& p) { return {tangentsOf(p.lens), rotationOf(p.orientation)}; }

Vec3d rayOf(const Projector& p, const ProjectorFrame& f, double px, double py) {
  // The image plane at distance 1 along the body's −z: the window's tangents at the image edges,
  // linear in between (a pinhole lens).
  const WindowTangents& t = f.t;
  const double x = t.left + (px / p.width) * (t.right - t.left);
  const double y = t.up - (py / p.height) * (t.up - t.down);
  const Rotation& r = f.r;
  const double v[3] = {x, y, -1};
  Vec3d out{};
  double* o[3] = {&out.x, &out.y, &out.z};
  for (int i = 0; i < 3; ++i) *o[i] = r.m[i][0] * v[0] + r.m[i][1] * v[1] + r.m[i][2] * v[2];
  const double len = std::sqrt(out.x * out.x + out.y * out.y + out.z * out.z);
  return {out.x / len, out.y / len, out.z / len};
}

}  // namespace

WindowTangents tangentsOf(const Window& w) {
  return {std::tan(w.leftDegrees * kToRadians), std::tan(w.rightDegrees * kToRadians),
          std::tan(w.downDegrees * kToRadians), std::tan(w.upDegrees * kToRadians)};
}

Vec3 Rotation::apply(double x, double y, double z) const {
  return {float(m[0][0] * x + m[0][1] * y + m[0][2] * z),
          float(m[1][0] * x + m[1][1] * y + m[1][2] * z),
          float(m[2][0] * x + m[2][1] * y + m[2][2] * z)};
}

Rotation rotationOf(const Orientation& o) {
  // As render::channelCamera: yaw right is a turn about −y, pitch up about +x, roll right (the
  // image's up leaning to +x) about −z, composed heading · pitch · bank.
  return multiply(multiply(aboutY(-o.yawDegrees * kToRadians), aboutX(o.pitchDegrees * kToRadians)),
                  aboutZ(-o.rollDegrees * kToRadians));
}

Orientation orientationOf(const Rotation& r) {
  // rotationOf(yaw, pitch, roll) = Ry(−yaw)·Rx(pitch)·Rz(−roll) looks along its third column
  // negated, (sin yaw · cos pitch, sin pitch, −cos yaw · cos pitch); what remains after the first
  // two turns, (Ry(−yaw)·Rx(pitch))ᵀ·r = Rz(−roll), holds the roll in its first column
  // (cos roll, −sin roll, 0).
  const double fx = -r.m[0][2], fy = -r.m[1][2], fz = -r.m[2][2];
  Orientation o;
  o.pitchDegrees = std::asin(std::clamp(fy, -1.0, 1.0)) * kToDegrees;
  o.yawDegrees = (std::fabs(fx) + std::fabs(fz) > 1e-12 ? std::atan2(fx, -fz) : 0) * kToDegrees;
  const Rotation base = rotationOf({o.yawDegrees, o.pitchDegrees, 0});
  double c0 = 0, c1 = 0;  // (baseᵀ·r)[0][0] and [1][0]
  for (int k = 0; k < 3; ++k) {
    c0 += base.m[k][0] * r.m[k][0];
    c1 += base.m[k][1] * r.m[k][0];
  }
  o.rollDegrees = std::atan2(-c1, c0) * kToDegrees;
  return o;
}

Vec3 projectorRay(const Projector& projector, double px, double py) {
  const Vec3d d = rayOf(projector, frameOf(projector), px, py);
  return {float(d.x), float(d.y), float(d.z)};
}

namespace {

// The screen point pixel (px, py) lights and the unit direction in which the eye sees it, in
// double; false when the pixel misses the screen or the eye sits on the screen point.
bool traceView(const DisplayGeometry& g, const ProjectorFrame& f, double px, double py,
               Vec3d& point, Vec3d& direction) {
  const Vec3d o = toDouble(g.projector.position);
  const Vec3d d = rayOf(g.projector, f, px, py);
  const double t = hitScreen(g.screen, o, d);
  if (t < 0) return false;
  point = {o.x + t * d.x, o.y + t * d.y, o.z + t * d.z};
  const Vec3d e{point.x - g.eye.x, point.y - g.eye.y, point.z - g.eye.z};
  const double len = std::sqrt(e.x * e.x + e.y * e.y + e.z * e.z);
  if (!(len > 0)) return false;  // the eye on the screen sees no direction
  direction = {e.x / len, e.y / len, e.z / len};
  return true;
}

}  // namespace

std::optional<Vec3d> screenPoint(const Screen& screen, Vec3d origin, Vec3d direction) {
  const double t = hitScreen(screen, origin, direction);
  if (t < 0) return std::nullopt;
  return origin + direction * t;
}

PixelView viewOfPixel(const DisplayGeometry& g, double px, double py) {
  Vec3d p{}, e{};
  if (!traceView(g, frameOf(g.projector), px, py, p, e)) return {};
  PixelView v;
  v.valid = true;
  v.screenPoint = {float(p.x), float(p.y), float(p.z)};
  v.direction = {float(e.x), float(e.y), float(e.z)};
  return v;
}

std::optional<Vec3d> viewDirection(const DisplayGeometry& g, double px, double py) {
  Vec3d p{}, e{};
  if (!traceView(g, frameOf(g.projector), px, py, p, e)) return std::nullopt;
  return e;
}

std::optional<Vec3d> pixelScreenPoint(const DisplayGeometry& g, double px, double py) {
  Vec3d p{}, e{};
  if (!traceView(g, frameOf(g.projector), px, py, p, e)) return std::nullopt;
  return p;
}

void viewDirections(const DisplayGeometry& g, std::vector<Vec3d>& directions,
                    std::vector<uint8_t>& valid) {
  viewDirections(g, 0, 0, g.projector.width, g.projector.height, directions, valid);
}

void viewDirections(const DisplayGeometry& g, int x0, int y0, int x1, int y1,
                    std::vector<Vec3d>& directions, std::vector<uint8_t>& valid) {
  const int w = x1 - x0, h = y1 - y0;
  directions.assign(size_t(w) * size_t(h), Vec3d{});
  valid.assign(directions.size(), 0);
  const ProjectorFrame frame = frameOf(g.projector);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      Vec3d p{}, e{};
      const size_t i = size_t(y) * size_t(w) + size_t(x);
      if (traceView(g, frame, x0 + x + 0.5, y0 + y + 0.5, p, e)) directions[i] = e, valid[i] = 1;
    }
}

DirectionMap directionMap(const DisplayGeometry& g) {
  DirectionMap map;
  map.width = g.projector.width;
  map.height = g.projector.height;
  std::vector<Vec3d> exact;
  viewDirections(g, exact, map.valid);
  map.directions.reserve(exact.size());
  for (const Vec3d& d : exact) map.directions.push_back({float(d.x), float(d.y), float(d.z)});
  return map;
}

CylinderRig threeProjectorCylinder(double radius, double overlapDegrees, int width, int height,
                                   double projectorHeight, double projectorBehind) {
  CylinderRig rig;
  rig.screen.shape = ScreenShape::cylinder;
  rig.screen.radius = radius;
  // A degree of screen beyond the outer projectors' edges, which land on ±(90 + overlap/2): an
  // edge ray then meets the screen whatever its rounding.
  rig.screen.minAzimuthDegrees = -91 - overlapDegrees / 2;
  rig.screen.maxAzimuthDegrees = 91 + overlapDegrees / 2;
  rig.screen.minHeight = -1.2;
  rig.screen.maxHeight = 1.2;
  // Heading, seen from the projectors' foot (0, ·, b), of the screen's azimuth φ: the point
  // (r sin φ, ·, −r cos φ) lies along (r sin φ, −(r cos φ + b)) — heading atan2(r sin φ, r cos φ + b).
  // With no pitch or roll a lens column of tangent tx heads exactly yaw + atan(tx), so the
  // window's left and right angles put the image's side edges on the chosen azimuths.
  const double r = radius, b = projectorBehind;
  auto heading = [&](double azimuthDegrees) {
    const double phi = azimuthDegrees * kToRadians;
    return std::atan2(r * std::sin(phi), r * std::cos(phi) + b) * kToDegrees;
  };
  for (int i = 0; i < 3; ++i) {
    const double centre = -60 + 60 * i, half = 30 + overlapDegrees / 2;
    Projector p;
    p.position = {0, float(projectorHeight), float(b)};
    p.width = width;
    p.height = height;
    p.orientation.yawDegrees = heading(centre);
    p.lens.leftDegrees = heading(centre - half) - p.orientation.yawDegrees;
    p.lens.rightDegrees = heading(centre + half) - p.orientation.yawDegrees;
    // Vertically: a ray of tangents (tx, ty) rises ty per unit of its direction's −z, and travels
    // D(tx)/√(1+tx²) of those before the wall, D the horizontal distance to the wall along its
    // heading. The top row must stay under the screen's top at every column: tan(up) is the least
    // (top − h)·√(1+tx²)/D over the columns (sampled, with 2% of the height to spare), and
    // likewise tan(down) at the bottom.
    const WindowTangents lens = tangentsOf(p.lens);
    const double tl = lens.left, tr = lens.right;
    double tanUp = 1e9, tanDown = -1e9;
    constexpr int kColumns = 512;
    for (int k = 0; k <= kColumns; ++k) {
      const double tx = tl + (tr - tl) * k / kColumns;
      const double phiHeading = (p.orientation.yawDegrees + std::atan(tx) * kToDegrees) * kToRadians;
      // The wall along that heading from (0, b): |(0, b) + s·(sin h, −cos h)| = r.
      const double bh = -b * std::cos(phiHeading);
      const double s = -bh + std::sqrt(bh * bh - (b * b - r * r));
      const double scale = std::sqrt(1 + tx * tx) / s;
      tanUp = std::min(tanUp, (0.98 * rig.screen.maxHeight - projectorHeight) * scale);
      tanDown = std::max(tanDown, (0.98 * rig.screen.minHeight - projectorHeight) * scale);
    }
    p.lens.upDegrees = std::atan(tanUp) * kToDegrees;
    p.lens.downDegrees = std::atan(tanDown) * kToDegrees;
    rig.projectors.push_back(p);
  }
  return rig;
}

}  // namespace sv::display
