// Projector rays against cylinder and dome screens, checked against points worked out by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "display/geometry.h"

namespace sv::display {
namespace {

constexpr double kPi = std::numbers::pi;
double rad(double degrees) { return degrees * kPi / 180; }

void expectNear(Vec3 a, Vec3 b, double eps = 1e-5) {
  EXPECT_NEAR(a.x, b.x, eps);
  EXPECT_NEAR(a.y, b.y, eps);
  EXPECT_NEAR(a.z, b.z, eps);
}

DisplayGeometry centred() {
  DisplayGeometry g;
  g.screen.radius = 3;
  g.projector.lens = {-30, 30, -20, 20};
  g.projector.width = 1280;
  g.projector.height = 800;
  return g;
}

TEST(Orientation, FollowsTheChannelConventions) {
  // Yaw 90 turns forward (−z) to the right (+x); pitch 90 to up; roll 90 leans up to the right.
  expectNear(rotationOf({90, 0, 0}).apply(0, 0, -1), {1, 0, 0});
  expectNear(rotationOf({0, 90, 0}).apply(0, 0, -1), {0, 1, 0});
  expectNear(rotationOf({0, 0, 90}).apply(0, 1, 0), {1, 0, 0});
  // Heading before pitch: yaw 90 then pitch 45 looks right and up.
  const double h = std::sqrt(0.5);
  expectNear(rotationOf({90, 45, 0}).apply(0, 0, -1), {float(h), float(h), 0});
}

TEST(Cylinder, CentrePixelFromTheAxisHitsStraightAhead) {
  const DisplayGeometry g = centred();
  const PixelView v = viewOfPixel(g, 640, 400);
  ASSERT_TRUE(v.valid);
  expectNear(v.screenPoint, {0, 0, -3});
  expectNear(v.direction, {0, 0, -1});
}

TEST(Cylinder, ProjectorAboveAndBehindTheEye) {
  // From (0, 0.5, 1) straight ahead: the wall at z = −3, height 0.5; the eye at the origin looks
  // along (0, 0.5, −3).
  DisplayGeometry g = centred();
  g.projector.position = {0, 0.5f, 1};
  const PixelView v = viewOfPixel(g, 640, 400);
  ASSERT_TRUE(v.valid);
  expectNear(v.screenPoint, {0, 0.5f, -3});
  const double n = std::sqrt(0.25 + 9);
  expectNear(v.direction, {0, float(0.5 / n), float(-3 / n)});
}

TEST(Cylinder, LeftEdgeColumnHeadsAlongTheLensAngle) {
  // px = 0 is the lens's left angle, −30°: from the axis the wall point is at azimuth −30.
  const DisplayGeometry g = centred();
  const PixelView v = viewOfPixel(g, 0, 400);
  ASSERT_TRUE(v.valid);
  expectNear(v.screenPoint, {float(-3 * std::sin(rad(30))), 0, float(-3 * std::cos(rad(30)))});
}

TEST(Cylinder, YawedProjectorAndOffsetEye) {
  DisplayGeometry g = centred();
  g.projector.orientation.yawDegrees = 90;
  g.eye = {0, 0, 0.5f};
  const PixelView v = viewOfPixel(g, 640, 400);
  ASSERT_TRUE(v.valid);
  expectNear(v.screenPoint, {3, 0, 0});
  const double n = std::sqrt(9 + 0.25);
  expectNear(v.direction, {float(3 / n), 0, float(-0.5 / n)});
}

TEST(Cylinder, RollTurnsTheTopRowToTheRight) {
  // Roll 90: the image's up points to +x, so the top-centre pixel (tangent up 20°) heads 20° right.
  DisplayGeometry g = centred();
  g.projector.orientation.rollDegrees = 90;
  const PixelView v = viewOfPixel(g, 640, 0);
  ASSERT_TRUE(v.valid);
  expectNear(v.screenPoint, {float(3 * std::sin(rad(20))), 0, float(-3 * std::cos(rad(20)))});
}

TEST(Cylinder, RaysBeyondTheExtentAreInvalid) {
  DisplayGeometry g = centred();
  g.projector.orientation.pitchDegrees = 80;  // meets the wall 3·tan 80 ≈ 17 m up: above 1.5
  EXPECT_FALSE(viewOfPixel(g, 640, 400).valid);
  g.projector.orientation = {120, 0, 0};  // azimuth 120: outside −90 … 90
  EXPECT_FALSE(viewOfPixel(g, 640, 400).valid);
  g.screen.maxAzimuthDegrees = 180;
  EXPECT_TRUE(viewOfPixel(g, 640, 400).valid);
}

TEST(Cylinder, FromOutsideTheNearWallIsHit) {
  // A projector 10 m in front of a cylinder facing it: the first wall met is the near one at
  // z = +3 (azimuth 180, which the extent must include).
  DisplayGeometry g = centred();
  g.screen.minAzimuthDegrees = -180;
  g.screen.maxAzimuthDegrees = 180;
  g.projector.position = {0, 0, 10};
  const PixelView v = viewOfPixel(g, 640, 400);
  ASSERT_TRUE(v.valid);
  expectNear(v.screenPoint, {0, 0, 3});
}

TEST(Dome, PitchedRayMeetsTheSphereAtItsElevation) {
  DisplayGeometry g = centred();
  g.screen.shape = ScreenShape::sphere;
  g.screen.radius = 5;
  g.projector.orientation.pitchDegrees = 45;
  g.eye = {0, -1, 0};
  const PixelView v = viewOfPixel(g, 640, 400);
  ASSERT_TRUE(v.valid);
  const float s = float(5 * std::sqrt(0.5));
  expectNear(v.screenPoint, {0, s, -s});
  const Vec3 d = Vec3{0, s, -s} - g.eye;
  expectNear(v.direction, normalize(d));
  g.projector.orientation.pitchDegrees = 70;  // elevation 70 > the dome's 60
  EXPECT_FALSE(viewOfPixel(g, 640, 400).valid);
}

TEST(Dome, OffCentreProjector) {
  // From (1, 0, 0) straight ahead: x = 1 on the sphere of radius 5 → z = −√24.
  DisplayGeometry g = centred();
  g.screen.shape = ScreenShape::sphere;
  g.screen.radius = 5;
  g.projector.position = {1, 0, 0};
  const PixelView v = viewOfPixel(g, 640, 400);
  ASSERT_TRUE(v.valid);
  expectNear(v.screenPoint, {1, 0, float(-std::sqrt(24.0))});
}

TEST(DirectionMap, HoldsEachPixelCentre) {
  DisplayGeometry g = centred();
  g.projector.width = 8;
  g.projector.height = 4;
  const DirectionMap m = directionMap(g);
  ASSERT_EQ(m.directions.size(), 32u);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) {
      const PixelView v = viewOfPixel(g, x + 0.5, y + 0.5);
      ASSERT_TRUE(m.isValid(x, y));
      EXPECT_EQ(m.direction(x, y), v.direction);
      EXPECT_NEAR(length(m.direction(x, y)), 1, 1e-6);
    }
}

TEST(ThreeProjectorCylinder, EveryPixelLandsOnTheScreenAndNeighboursOverlap) {
  const double overlap = 10;
  const CylinderRig rig = threeProjectorCylinder(3, overlap, 160, 100);
  ASSERT_EQ(rig.projectors.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    const DisplayGeometry g = rig.geometry(i);
    const DirectionMap m = directionMap(g);
    for (int y = 0; y < 100; ++y)
      for (int x = 0; x < 160; ++x) ASSERT_TRUE(m.isValid(x, y)) << i << " " << x << " " << y;
    // The image's side edges land on the designed azimuths (any row: no pitch or roll).
    for (double py : {0.0, 50.0, 100.0}) {
      const PixelView left = viewOfPixel(g, 0, py), right = viewOfPixel(g, 160, py);
      ASSERT_TRUE(left.valid && right.valid);
      EXPECT_NEAR(std::atan2(left.screenPoint.x, -left.screenPoint.z) * 180 / kPi,
                  -90 + 60 * i - overlap / 2, 1e-3);
      EXPECT_NEAR(std::atan2(right.screenPoint.x, -right.screenPoint.z) * 180 / kPi,
                  -30 + 60 * i + overlap / 2, 1e-3);
    }
    // The lenses use the screen's height: the top-centre pixel within 5% of the top.
    EXPECT_GT(viewOfPixel(g, 80, 0).screenPoint.y, 0.9 * rig.screen.maxHeight);
  }
}

}  // namespace
}  // namespace sv::display
