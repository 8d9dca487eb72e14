// Light points (SPEC §13): the runway, approach, taxiway and city lights, beacons and stars of a
// simulator's night — tiny, very bright, anti-aliased points, attenuated by distance and fog,
// optionally directional and blinking, depth-tested against the scene, added in linear light.
// Plain records (public API), shared by the scene (which holds them) and the light pass (which
// draws them); the laws they obey are in docs/lights.md and lights/light_laws.h.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "synthvis/math.h"

namespace sv::scene {

// Blinking: on while frac(t / period + phase) < onFraction, t the scene's simulation time in
// seconds (Scene::time) — so a frame is reproducible from its time. period 0: always on.
struct LightBlink {
  float period = 0;       // seconds
  float phase = 0;        // turns (0 … 1), added to each light's own phase (LightPoint::phase)
  float onFraction = 1;   // of the period, (0, 1]
};

// What a light looks like; many lights share one (a string of runway edge lights, a PAPI box).
struct LightAppearance {
  std::string name;
  Vec3 color{1, 1, 1};     // linear, at full intensity
  float intensity = 200;   // candela, on the lobe's axis
  // Directional lights shine in an elliptical cone about `direction`: seen at horizontal and
  // vertical angles whose tangents over the axis component are x and y, with t = (x / tan(H/2))² +
  // (y / tan(V/2))² the intensity is I·(1 − t)^falloff inside (t < 1), 0 outside. H, V: the lobe's
  // full widths, in (0, 180) degrees; the horizontal is about world up (+y).
  bool directional = false;
  Vec3 direction{0, 0, -1};    // world; the way the light shines (normalised by loaders)
  float horizontalLobe = 30;   // degrees, full width
  float verticalLobe = 15;     // degrees, full width
  float falloff = 1;
  // Seen from behind: the same lobe about −direction, in `backColor` (a bidirectional edge light
  // whose far side is red or yellow); false: dark from behind.
  bool backLobe = false;
  Vec3 backColor{1, 0, 0};
  // Colour by the viewer's elevation (a PAPI unit): seen from below `splitAngle` degrees above the
  // light's horizontal plane it shows `lowColor`, from above `color`, blended linearly across
  // `splitWidth` degrees centred on the split.
  bool split = false;
  float splitAngle = 3;
  float splitWidth = 0.05f;
  Vec3 lowColor{1, 0, 0};
  LightBlink blink;
  // A rotating beacon: the lobe turns about world up once per `rotationPeriod` seconds (0: fixed),
  // starting from `direction` at t = 0, advanced by the light's phase.
  float rotationPeriod = 0;
};

// At most this many light points in a scene (32 bytes each): loaders refuse more.
inline constexpr size_t kMaxLightPoints = size_t(1) << 22;

// One light. `phase` (turns) is added to its appearance's blink and rotation phases: a sequenced
// flasher string gives each light its place in the sequence.
struct LightPoint {
  Vec3 position;            // world
  uint32_t appearance = 0;  // index into Scene::lightAppearances
  float phase = 0;
  int32_t group = -1;       // index into Scene::lightGroups, or −1 (always on, undimmed)
};

// A set of lights the host switches and dims together (runway lights, approach, city).
struct LightGroup {
  std::string name;
  bool on = true;
  float dim = 1;  // intensity multiplier, [0, 1]
};

// How light points become pixels (docs/lights.md).
struct LightSettings {
  // The illuminance at the eye E = I·T / d² (lux; I candela, d metres, T the fog's transmission)
  // becomes an on-screen energy Φ = exposure · E: Φ pixels of full white. Its natural size is
  // the disc of area Φ, clamped to [minSize, maxSize] pixels of diameter.
  float exposure = 5000;
  float minSize = 1.5f, maxSize = 8;
  // Fog on lights: T = 2^(−β · punchThrough · d) — lights are seen through fog farther than
  // surfaces (1: as far; smaller: farther).
  float punchThrough = 0.5f;
  // A light is hidden where the surface in its pixel is nearer than it by more than this
  // (metres) plus the surface's own depth spread around the pixel (so a light on grazing ground
  // stays lit; a wall in front hides it).
  float depthBias = 0.5f;
};

// The stars: the catalogue's directions in equatorial coordinates (x toward RA 0h Dec 0°, z
// toward the north celestial pole), placed in the sky of an observer at `latitude` with local
// sidereal time `siderealTime` hours at scene time 0 (advancing 1.0027379 h per hour of time).
// World axes: +y up, −z north, +x east. Drawn only where nothing else is (the background), not
// fogged; a star of magnitude m has Φ = brightness · 10^(−0.4·m).
struct Star {
  Vec3 direction;    // equatorial, unit
  float magnitude = 0;
  Vec3 color{1, 1, 1};  // linear, of unit luminance-ish (from the colour index, or white)
};

struct StarField {
  std::vector<Star> stars;
  float latitude = 45;      // degrees north
  float siderealTime = 0;   // hours
  float brightness = 3;     // Φ of a magnitude-0 star
  float limit = 6.5f;       // fainter stars are not drawn
};

}  // namespace sv::scene
