// The laws of SPEC §13 as docs/lights.md states them, each against its formula.
#include "lights/light_laws.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace sv::lights {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

Vec3 fromAngles(float azimuthDegrees, float elevationDegrees) {
  // Azimuth from −z (north) toward +x (east); a light shining north is seen from the south.
  const float a = azimuthDegrees * kPi / 180, e = elevationDegrees * kPi / 180;
  return {std::cos(e) * std::sin(a), std::sin(e), -std::cos(e) * std::cos(a)};
}

TEST(LightLaws, BlinkStateAtGivenTimes) {
  const scene::LightBlink b{.period = 2, .phase = 0.25f, .onFraction = 0.5f};
  // frac(t/2 + 0.25) < 0.5: on for t in [0, 0.5) and [1.5, 2.5) …
  EXPECT_TRUE(blinkOn(b, 0, 0.0));
  EXPECT_TRUE(blinkOn(b, 0, 0.49));
  EXPECT_FALSE(blinkOn(b, 0, 0.51));
  EXPECT_FALSE(blinkOn(b, 0, 1.49));
  EXPECT_TRUE(blinkOn(b, 0, 1.51));
  EXPECT_TRUE(blinkOn(b, 0, 100.0));   // 50.25 → 0.25
  EXPECT_FALSE(blinkOn(b, 0, 101.0));  // 50.75
  // The light's own phase shifts it: a sequence of 4 flashers, each a quarter period later.
  const scene::LightBlink flash{.period = 0.5f, .phase = 0, .onFraction = 0.1f};
  for (int k = 0; k < 4; ++k)
    for (int m = 0; m < 4; ++m)
      EXPECT_EQ(blinkOn(flash, -float(k) / 4, 0.5 * m / 4 + 0.01), k == m) << k << " " << m;
  EXPECT_TRUE(blinkOn(scene::LightBlink{}, 0, 12345.6));  // steady
}

TEST(LightLaws, LobeFactorFollowsTheEllipse) {
  const Vec3 north{0, 0, -1};
  // Seen along the axis: the full intensity; at the lobe's half-widths: zero.
  EXPECT_FLOAT_EQ(lobeFactor(north, fromAngles(0, 0), 30, 10, 1), 1);
  EXPECT_NEAR(lobeFactor(north, fromAngles(15, 0), 30, 10, 1), 0, 1e-5);
  EXPECT_NEAR(lobeFactor(north, fromAngles(0, 5), 30, 10, 1), 0, 1e-5);
  EXPECT_EQ(lobeFactor(north, fromAngles(20, 0), 30, 10, 1), 0);
  EXPECT_EQ(lobeFactor(north, fromAngles(180, 0), 30, 10, 1), 0);  // behind
  // Inside: 1 − t with t = (tan h / tan 15°)² + (tan v / tan 5°)² (h, v small enough that the
  // tangents over the axis are the angles' own).
  const Vec3 d = fromAngles(7, 0);
  const float t = std::pow(std::tan(7 * kPi / 180) / std::tan(15 * kPi / 180), 2.0f);
  EXPECT_NEAR(lobeFactor(north, d, 30, 10, 1), 1 - t, 1e-5);
  EXPECT_NEAR(lobeFactor(north, d, 30, 10, 2.5f), std::pow(1 - t, 2.5f), 1e-5);
}

TEST(LightLaws, PapiColourChangesWithTheViewingAngle) {
  scene::LightAppearance a;
  a.color = {1, 1, 1};
  a.directional = true;
  a.direction = {0, 0, 1};  // shining south, toward the approach
  a.horizontalLobe = 30;
  a.verticalLobe = 20;
  a.split = true;
  a.splitAngle = 3;
  a.splitWidth = 0.2f;
  a.lowColor = {1, 0, 0};
  auto seen = [&](float elevation) {
    const Vec3 d = fromAngles(180, elevation);  // from the south, `elevation` degrees up
    const float lobe = lobeFactor(a.direction, d, 30, 20, 1);
    const Vec3 c = appearanceColor(a, a.direction, d);
    return Vec3{c.x / lobe, c.y / lobe, c.z / lobe};
  };
  const Vec3 low = seen(2.5f), high = seen(3.5f), mid = seen(3);
  EXPECT_NEAR(low.x, 1, 1e-5);  // red below
  EXPECT_NEAR(low.y, 0, 1e-5);
  EXPECT_NEAR(high.y, 1, 1e-5);  // white above
  EXPECT_NEAR(high.z, 1, 1e-5);
  EXPECT_NEAR(mid.y, 0.5, 0.02);  // half-way in the transition
  EXPECT_NEAR(seen(2.95f).y, 0.25, 0.02);
  // A back lobe shows its own colour from behind; none: dark.
  const Vec3 behind = fromAngles(0, 1);
  EXPECT_EQ(appearanceColor(a, a.direction, behind).x, 0);
  a.backLobe = true;
  a.backColor = {0, 1, 0};
  a.split = false;
  const Vec3 back = appearanceColor(a, a.direction, behind);
  EXPECT_EQ(back.x, 0);
  EXPECT_GT(back.y, 0.9f);
}

TEST(LightLaws, RotatingBeaconTurnsItsLobe) {
  scene::LightAppearance a;
  a.directional = true;
  a.direction = {1, 0, 0};  // east at t = 0
  a.rotationPeriod = 4;
  auto near = [](Vec3 u, Vec3 v) { return length(u - v) < 1e-5f; };
  EXPECT_TRUE(near(lobeAxis(a, 0, 0), {1, 0, 0}));
  EXPECT_TRUE(near(lobeAxis(a, 0, 1), {0, 0, 1}));   // a quarter turn: south
  EXPECT_TRUE(near(lobeAxis(a, 0, 2), {-1, 0, 0}));  // west
  EXPECT_TRUE(near(lobeAxis(a, 0.25f, 0), {0, 0, 1}));
  a.rotationPeriod = 0;
  EXPECT_TRUE(near(lobeAxis(a, 0.25f, 3), {1, 0, 0}));
}

TEST(LightLaws, FogSizeAndEnergyFollowTheirFormulas) {
  // T = 2^(−β·p·d): with β = 0.001, p = 0.5, d = 2000 the light keeps half.
  EXPECT_FLOAT_EQ(fogTransmission(0.001f, 0.5f, 2000), 0.5f);
  EXPECT_FLOAT_EQ(fogTransmission(0.001f, 1, 2000), 0.25f);  // surfaces' law at p = 1
  EXPECT_FLOAT_EQ(fogTransmission(0, 0.5f, 1e6f), 1);
  // Φ = exposure · I · T / d².
  EXPECT_FLOAT_EQ(screenEnergy(5000, 200, 0.5f, 1000), 5000 * 200 * 0.5f / 1e6f);
  // D = 2·(15/16)·√Φ − 1 clamped: Φ = (16/15 · 3)² gives R = 3, D = 5.
  EXPECT_FLOAT_EQ(splatDiameter(std::pow(16.0f / 15 * 3, 2.0f), 1, 8), 5);
  EXPECT_FLOAT_EQ(splatDiameter(0.01f, 1.5f, 8), 1.5f);
  EXPECT_FLOAT_EQ(splatDiameter(1e6f, 1.5f, 8), 8);
  EXPECT_FLOAT_EQ(splatRadius(2), 1.5f);
  // The kernel along an axis: (1 − t²/R²)², 1 at the centre, 0 at and beyond R.
  EXPECT_FLOAT_EQ(splatWeight(0, 0.25f), 1);
  EXPECT_FLOAT_EQ(splatWeight(1, 0.25f), 0.5625f);
  EXPECT_EQ(splatWeight(4, 0.25f), 0);
  // The sum over the square is the product of the axes' sums: at (10.5, 20.5), R = 2, each axis
  // has centres at distances 0, ±1 (and ±2, weight 0): 1 + 2·0.5625.
  EXPECT_FLOAT_EQ(splatWeightSum(10.5f, 20.5f, 2), 2.125f * 2.125f);
  EXPECT_EQ(splatWeight(5, 0.25f), 0);
}

TEST(LightLaws, StarsTurnWithTheSky) {
  // The celestial pole stands at the latitude's altitude, due north, at any time.
  for (double t : {0.0, 3600.0, 40000.0}) {
    const Vec3 pole = starDirection({0, 0, 1}, 52, 5.5, t);
    EXPECT_NEAR(pole.y, std::sin(52 * kPi / 180), 1e-5);
    EXPECT_NEAR(pole.z, -std::cos(52 * kPi / 180), 1e-5);
    EXPECT_NEAR(pole.x, 0, 1e-5);
  }
  // A star on the equator at RA = LST is on the meridian: due south at altitude 90° − latitude.
  const float lst = 6;  // hours; RA 6h is equatorial +y
  const Vec3 s = starDirection({0, 1, 0}, 40, lst, 0);
  EXPECT_NEAR(s.y, std::sin(50 * kPi / 180), 1e-5);
  EXPECT_NEAR(s.z, std::cos(50 * kPi / 180), 1e-5);
  EXPECT_NEAR(s.x, 0, 1e-5);
  // Six sidereal hours later it sets in the west (−x).
  const Vec3 w = starDirection({0, 1, 0}, 40, lst, 6 * 3600 / 1.0027379);
  EXPECT_NEAR(w.y, 0, 1e-4);
  EXPECT_NEAR(w.x, -1, 1e-4);
}

}  // namespace
}  // namespace sv::lights
