// Where a host's coordinates land in the database (docs/ig.md, "Coordinates"). CIGI places
// top-level entities geodetically (latitude, longitude in degrees, altitude in metres) and turns
// them by heading (yaw, clockwise from north), pitch (nose up) and roll (right wing down) — body
// axes x forward, y right, z down; children by offsets in their parent's body axes. synthvis's
// world is +x east, +y up, −z north (scene-format.md). The database's origin (its geodetic frame,
// or a latitude, longitude and altitude in the IG configuration) is the world origin, and
// geodetic positions map into the world by that frame (synthvis/geodesy.h: WGS 84, the one
// conversion the terrain's geographic tables are placed by too).
#pragma once

#include <cmath>
#include <numbers>

#include "synthvis/geodesy.h"
#include "synthvis/math.h"

namespace sv::ig {

// A rotation as three world-space columns: the body's forward, right and down axes.
struct Frame3 {
  Vec3d forward{0, 0, -1}, right{1, 0, 0}, down{0, -1, 0};
  Vec3d apply(Vec3d body) const { return forward * body.x + right * body.y + down * body.z; }
};

// Heading ψ, pitch θ, roll φ (degrees) as body axes in a parent frame (z-y-x Euler angles, as
// CIGI and aviation define them: turn by heading about down, then pitch about the new right, then
// roll about the new forward).
inline Frame3 eulerFrame(const Frame3& parent, double yawDeg, double pitchDeg, double rollDeg) {
  constexpr double rad = std::numbers::pi / 180;
  const double cy = std::cos(yawDeg * rad), sy = std::sin(yawDeg * rad);
  const double cp = std::cos(pitchDeg * rad), sp = std::sin(pitchDeg * rad);
  const double cr = std::cos(rollDeg * rad), sr = std::sin(rollDeg * rad);
  // Body axes in the parent's (forward, right, down) components: the columns of Rz(ψ)Ry(θ)Rx(φ).
  const Vec3d f{cy * cp, sy * cp, -sp};
  const Vec3d r{cy * sp * sr - sy * cr, sy * sp * sr + cy * cr, cp * sr};
  const Vec3d d{cy * sp * cr + sy * sr, sy * sp * cr - cy * sr, cp * cr};
  return {parent.apply(f), parent.apply(r), parent.apply(d)};
}

// The local level frame at the origin: forward north, right east, down (world −y).
inline Frame3 levelFrame() { return {{0, 0, -1}, {1, 0, 0}, {0, -1, 0}}; }

// A model's placement: model files use glTF's axes (+y up, +z the model's front, −x its right,
// docs/ig.md), so model +z is body forward, −x body right, −y body down.
inline Mat4 modelMatrix(const Frame3& body, Vec3d position) {
  const Vec3d mx = body.right * -1.0, my = body.down * -1.0, mz = body.forward;
  Mat4 m;
  const Vec3d cols[3] = {mx, my, mz};
  for (int c = 0; c < 3; ++c) {
    m.m[c][0] = float(cols[c].x);
    m.m[c][1] = float(cols[c].y);
    m.m[c][2] = float(cols[c].z);
  }
  m.m[3][0] = float(position.x);
  m.m[3][1] = float(position.y);
  m.m[3][2] = float(position.z);
  return m;
}

}  // namespace sv::ig
