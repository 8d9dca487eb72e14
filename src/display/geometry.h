// Display geometry (SPEC §9 display channels, §12 distortion correction; issue 34 item 1): for
// each pixel of a projector lighting a curved screen, the point of the screen it lights and the
// direction in which the eye sees that point. Later stages build from it the sub-frustum
// projective maps of SPEC §12 and the warp maps of the resampling method.
//
// Frame: every position and direction here is in the scene camera's eye space — x right, y up,
// z toward the viewer (the camera looks down −z), metres — the frame of Channel::offset
// (synthvis/scene.h). Angles are degrees.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "synthvis/math.h"

namespace sv::display {

// An orientation as Channel's (synthvis/scene.h): heading, then pitch, then bank about the body's
// own axes; yaw positive turns to the right, pitch positive up, roll positive leans the image's up
// to the right. All zero: looking down −z with y up.
struct Orientation {
  double yawDegrees = 0, pitchDegrees = 0, rollDegrees = 0;
};

// A possibly asymmetric window, as ChannelFrustum: signed half-angles from the axis, left < right,
// down < up, each in (−90, 90).
struct Window {
  double leftDegrees = -30, rightDegrees = 30, downDegrees = -20, upDegrees = 20;
};

// The tangents of a window's half-angles: its edges on the image plane at distance 1.
struct WindowTangents {
  double left, right, down, up;
};
WindowTangents tangentsOf(const Window& w);

// A projector: where it stands, where it points, its lens and its pixels. Pixel (px, py) is
// continuous, origin at the top-left corner of the image, x right, y down; pixel centres are at
// +0.5. The lens's window spans the image edges: px = 0 is leftDegrees, py = 0 is upDegrees.
struct Projector {
  Vec3 position{0, 0, 0};
  Orientation orientation;
  Window lens;
  int width = 1280, height = 800;
};

// The screen: part of a vertical cylinder (axis along y through `centre`) or of a sphere (a dome),
// seen from inside. Azimuth is measured about the y axis from −z (straight ahead, 0) toward +x
// (positive, to the right), −180 … 180; elevation from the horizontal plane through the centre
// toward +y. A point lies on the screen when its azimuth is within [minAzimuth, maxAzimuth] and,
// for the cylinder, its height above the centre within [minHeight, maxHeight] metres, for the
// sphere its elevation within [minElevation, maxElevation].
enum class ScreenShape : uint8_t { cylinder, sphere };
struct Screen {
  ScreenShape shape = ScreenShape::cylinder;
  Vec3 centre{0, 0, 0};
  double radius = 3;
  double minAzimuthDegrees = -90, maxAzimuthDegrees = 90;
  double minHeight = -1.5, maxHeight = 1.5;                 // cylinder
  double minElevationDegrees = -30, maxElevationDegrees = 60;  // sphere
};

// One projector, its screen and the eye that looks at the screen.
struct DisplayGeometry {
  Screen screen;
  Projector projector;
  Vec3 eye{0, 0, 0};
};

// What pixel (px, py) shows. `valid` is false when the pixel's ray misses the screen (beyond its
// extent, or no intersection in front of the projector); the other members are then zero.
// Where the ray from `origin` along `direction` (any length) first meets the screen within its
// extent, in front of the origin; nothing when it misses.
std::optional<Vec3d> screenPoint(const Screen& screen, Vec3d origin, Vec3d direction);

struct PixelView {
  bool valid = false;
  Vec3 screenPoint;  // where the ray from the projector first meets the screen
  Vec3 direction;    // unit vector from the eye to screenPoint
};
PixelView viewOfPixel(const DisplayGeometry& geometry, double px, double py);

// viewOfPixel's direction in double, before its rounding to float (nothing when the pixel is
// invalid): for the sub-frustum maps, whose residuals are measured far below float's 6e-8.
std::optional<Vec3d> viewDirection(const DisplayGeometry& geometry, double px, double py);
// The screen point pixel (px, py) lights, in double (nothing when it misses the screen): what a
// moved eye sees the pixel along (the sub-frustum plan's refit, display/subfrustum.h).
std::optional<Vec3d> pixelScreenPoint(const DisplayGeometry& geometry, double px, double py);
// viewDirection at every pixel centre, row by row from the top (x fastest); (0, 0, 0) and valid 0
// where the pixel misses the screen. The projector's rotation and lens are made once, not per
// pixel.
void viewDirections(const DisplayGeometry& geometry, std::vector<Vec3d>& directions,
                    std::vector<uint8_t>& valid);
// The same for the pixels [x0, x1) × [y0, y1) alone, row by row (a sub-frustum cell's).
void viewDirections(const DisplayGeometry& geometry, int x0, int y0, int x1, int y1,
                    std::vector<Vec3d>& directions, std::vector<uint8_t>& valid);

// The unit ray leaving a projector through its pixel (px, py), in the eye frame.
Vec3 projectorRay(const Projector& projector, double px, double py);

// The rotation taking a body's axes (x right, y up, −z forward) to the eye frame, for an
// orientation; the same composition as render::channelCamera's placement of a channel.
struct Rotation {
  double m[3][3];  // m[row][col]: v_eye = m · v_body
  Vec3 apply(double x, double y, double z) const;
};
Rotation rotationOf(const Orientation& o);
// The orientation of a rotation (orthonormal, determinant 1): rotationOf(orientationOf(r)) is r.
// Pitch within [−90, 90]; at ±90 (looking straight up or down) yaw is taken as 0.
Orientation orientationOf(const Rotation& r);

// The view of every pixel centre of a display: directions (unit, eye frame) row by row from the
// top, and whether each is valid (an invalid pixel's direction is zero).
struct DirectionMap {
  int width = 0, height = 0;
  std::vector<Vec3> directions;
  std::vector<uint8_t> valid;
  Vec3 direction(int x, int y) const { return directions[size_t(y) * size_t(width) + size_t(x)]; }
  bool isValid(int x, int y) const { return valid[size_t(y) * size_t(width) + size_t(x)] != 0; }
};
DirectionMap directionMap(const DisplayGeometry& geometry);

// The demo configuration of issue 34: a cylinder of `radius` metres around the eye (at the
// origin, on the axis), lit by three projectors of width × height pixels standing together
// `projectorHeight` metres above and `projectorBehind` metres behind the eye. Projector i
// (0 = left) covers the azimuths [−90 + 60·i − overlap/2, −30 + 60·i + overlap/2] at eye height,
// so neighbours share `overlapDegrees` of screen; the screen spans 180° plus overlap/2 + 1° at each
// end and 1.2 m above and below the eye, and the lenses keep every pixel on it.
struct CylinderRig {
  Screen screen;
  Vec3 eye{0, 0, 0};
  std::vector<Projector> projectors;
  DisplayGeometry geometry(int i) const { return {screen, projectors[size_t(i)], eye}; }
};
CylinderRig threeProjectorCylinder(double radius = 3, double overlapDegrees = 10, int width = 1280,
                                   int height = 800, double projectorHeight = 0.4,
                                   double projectorBehind = 0.5);

}  // namespace sv::display
