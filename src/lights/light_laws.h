// The laws a light point obeys (SPEC §13, docs/lights.md): blinking, lobes, fog, on-screen size
// and energy, the splat's weights, the stars' sky. Pure functions, each tested against its
// formula (tests/lights/light_laws_test.cpp); the pass (light_pass.h) applies them per frame.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include "synthvis/light_points.h"

namespace sv::lights {

// Whether a blinking light is lit at time `t` (seconds): frac(t / period + phase) < onFraction,
// phase the appearance's plus the light's own (turns). Steady lights (period 0) always are.
inline bool blinkOn(const scene::LightBlink& b, float lightPhase, double t) {
  if (!(b.period > 0)) return true;
  const double u = t / double(b.period) + double(b.phase) + double(lightPhase);
  return u - std::floor(u) < double(b.onFraction);
}

// The lobe's axis at time t: `direction`, or for a rotating beacon `direction` turned about
// world up by 2π·(t / rotationPeriod + lightPhase), from +x (east) toward +z (south): clockwise
// seen from above, as beacons turn.
inline Vec3 lobeAxis(const scene::LightAppearance& a, float lightPhase, double t) {
  if (!(a.rotationPeriod > 0)) return a.direction;
  const double turns = t / double(a.rotationPeriod) + double(lightPhase);
  const double angle = 2 * std::numbers::pi * (turns - std::floor(turns));
  const double c = std::cos(angle), s = std::sin(angle);
  const Vec3 d = a.direction;
  return {float(c * d.x - s * d.z), d.y, float(s * d.x + c * d.z)};
}

// A directional light's factor toward a viewer in unit direction `toViewer` (from the light),
// for a lobe about unit `axis`: (1 − t)^falloff with t = (x / tan(H/2))² + (y / tan(V/2))², where
// x, y, z are `toViewer` in the lobe's frame (z along the axis, x horizontal — perpendicular to
// the axis and world up — y the rest) and x, y are taken over z; 0 where z ≤ 0 or t ≥ 1.
// The tangents of a lobe's half-widths (the same for every light of an appearance: worked out
// once a frame, not per light).
struct LobeTangents {
  float horizontal = 1, vertical = 1;
};
inline LobeTangents lobeTangents(float horizontalLobe, float verticalLobe) {
  return {std::tan(horizontalLobe * (std::numbers::pi_v<float> / 360)),
          std::tan(verticalLobe * (std::numbers::pi_v<float> / 360))};
}

inline float lobeFactor(Vec3 axis, Vec3 toViewer, LobeTangents tangents, float falloff) {
  const float z = dot(axis, toViewer);
  if (!(z > 0)) return 0;
  Vec3 right = cross(axis, Vec3{0, 1, 0});
  const float r2 = dot(right, right);
  right = r2 > 1e-12f ? right * (1 / std::sqrt(r2)) : Vec3{1, 0, 0};  // a vertical axis: +x
  const Vec3 up = cross(right, axis);
  const float x = dot(right, toViewer) / (z * tangents.horizontal);
  const float y = dot(up, toViewer) / (z * tangents.vertical);
  const float t = x * x + y * y;
  if (!(t < 1)) return 0;
  return falloff == 1 ? 1 - t : std::pow(1 - t, falloff);
}
inline float lobeFactor(Vec3 axis, Vec3 toViewer, float horizontalLobe, float verticalLobe,
                        float falloff) {
  return lobeFactor(axis, toViewer, lobeTangents(horizontalLobe, verticalLobe), falloff);
}

// The colour a light shows a viewer in unit direction `toViewer` (from the light), times its
// lobe factor: the front lobe in `color` (or, split, blended toward `lowColor` below the split
// elevation), the back lobe in `backColor`; an omnidirectional light is `color` everywhere.
// `tangents`: the appearance's lobeTangents.
inline Vec3 appearanceColor(const scene::LightAppearance& a, Vec3 axis, Vec3 toViewer,
                            LobeTangents tangents) {
  Vec3 front = a.color;
  if (a.split) {
    // Elevation of the viewer above the light's horizontal plane, degrees.
    const float elevation =
        std::asin(std::clamp(toViewer.y, -1.0f, 1.0f)) * (180 / std::numbers::pi_v<float>);
    const float w = std::max(a.splitWidth, 1e-6f);
    const float high = std::clamp((elevation - a.splitAngle) / w + 0.5f, 0.0f, 1.0f);
    front = a.lowColor * (1 - high) + a.color * high;
  }
  if (!a.directional) return front;
  const float f = lobeFactor(axis, toViewer, tangents, a.falloff);
  if (f > 0) return front * f;
  if (!a.backLobe) return {};
  return a.backColor * lobeFactor(-axis, toViewer, tangents, a.falloff);
}
inline Vec3 appearanceColor(const scene::LightAppearance& a, Vec3 axis, Vec3 toViewer) {
  return appearanceColor(a, axis, toViewer, lobeTangents(a.horizontalLobe, a.verticalLobe));
}

// The fog's transmission for a light at distance d: 2^(−β · punchThrough · d) (SPEC §8's law
// with the light's punch-through, docs/lights.md).
inline float fogTransmission(float beta, float punchThrough, float d) {
  return beta > 0 ? std::exp2(-beta * punchThrough * d) : 1.0f;
}

// The on-screen energy of a light of intensity I candela at d metres, transmission T:
// Φ = exposure · I · T / d² (pixels of full white).
inline float screenEnergy(float exposure, float intensity, float transmission, float d) {
  return exposure * intensity * transmission / (d * d);
}

// The splat's kernel is separable (its weights, and their sum, come from two short rows): the
// product k(dx)·k(dy) of k(t) = (1 − t²/R²)² for |t| < R — round enough at the sizes lights are
// drawn, and smooth to its edge. A pixel's share of the energy is its weight over the sum of the
// weights of every pixel centre in the kernel's square (so the total is Φ wherever the light
// falls). ∫k = 16R/15, so the kernel's integral is (16R/15)².

// The diameter a light of energy Φ is drawn at: its natural size — the kernel whose peak is full
// white carries Φ when (16R/15)² = Φ, R = (15/16)·√Φ, and the diameter is 2R − 1 (splatRadius's
// inverse) — clamped to [minSize, maxSize]. Below the minimum the light keeps the minimum size
// and its energy, and fades; above the maximum it brightens.
inline float splatDiameter(float energy, float minSize, float maxSize) {
  return std::clamp(2 * (15.0f / 16) * std::sqrt(energy) - 1, minSize, maxSize);
}

// The splat's kernel radius for a diameter D: the disc widened by half a pixel, so that a 1-px
// light still reaches the pixel centres around it (the aperture of SPEC §3.2).
inline float splatRadius(float diameter) { return 0.5f * diameter + 0.5f; }

// The kernel along one axis at squared distance t² (1/R² given): (1 − t²/R²)², 0 from R on.
inline float splatWeight(float t2, float invR2) {
  const float u = 1 - t2 * invR2;
  return u > 0 ? u * u : 0;
}

// ⌊x⌋ for |x| < 2³¹, without a call (the baseline target has no rounding instruction).
inline int floorToInt(float x) {
  const int i = int(x);
  return i - (float(i) > x);
}

// The largest number of pixel centres a kernel spans along an axis (radius ≤ 32.5: sizes ≤ 64).
inline constexpr int kMaxSplatSpan = 66;

// The kernel's weights along one axis for a light at coordinate c with radius R: out[k] for the
// pixel centres first + k + ½, k < the returned count (those in [c − R, c + R]).
inline int splatAxis(float c, float radius, float* out, int& first) {
  const float invR2 = 1 / (radius * radius);
  first = floorToInt(c - radius);
  const int last = floorToInt(c + radius);
  int n = 0;
  for (int i = first; i <= last && n < kMaxSplatSpan; ++i) {
    const float d = float(i) + 0.5f - c;
    out[n++] = splatWeight(d * d, invR2);
  }
  return n;
}

// splatAxis for a kernel of radius ≤ kSmallSplatRadius — the common light, near the minimum size:
// the same weights, four of them always (those past the span are 0: their centres lie farther
// than R), without a loop or a branch to mispredict.
inline constexpr float kSmallSplatRadius = 1.5f;
inline int splatAxis4(float c, float radius, float out[4], int& first) {
  const float invR2 = 1 / (radius * radius);
  first = floorToInt(c - radius);
  for (int k = 0; k < 4; ++k) {
    const float d = float(first + k) + 0.5f - c;
    out[k] = splatWeight(d * d, invR2);
  }
  return floorToInt(c + radius) - first + 1;
}

// The sum of the kernel's weights over the pixel centres around (x, y): a product of two sums.
inline float splatWeightSum(float x, float y, float radius) {
  float w[kMaxSplatSpan];
  int first;
  float sx = 0, sy = 0;
  const int nx = splatAxis(x, radius, w, first);
  for (int k = 0; k < nx; ++k) sx += w[k];
  const int ny = splatAxis(y, radius, w, first);
  for (int k = 0; k < ny; ++k) sy += w[k];
  return sx * sy;
}

// A star's world direction at time t (seconds): equatorial `e` (x toward RA 0h, z toward the
// celestial pole) turned by the local sidereal time into the observer's horizon frame, then to
// world axes (+y up, −z north, +x east).
inline Vec3 starDirection(Vec3 e, float latitudeDegrees, double siderealHours, double t) {
  const double lst = siderealHours + t * (1.0027379 / 3600);  // hours
  const double theta = lst * (std::numbers::pi / 12);          // the hour angle of RA 0h
  // Hour-angle frame: x toward the meridian (hour angle 0), y toward the west (hour angle 6h).
  const double c = std::cos(theta), s = std::sin(theta);
  const double hx = c * e.x + s * e.y, hy = s * e.x - c * e.y, hz = e.z;
  // To the horizon: south, west, zenith components.
  const double phi = double(latitudeDegrees) * (std::numbers::pi / 180);
  const double sp = std::sin(phi), cp = std::cos(phi);
  const double south = sp * hx - cp * hz, west = hy, zenith = cp * hx + sp * hz;
  return {float(-west), float(zenith), float(south)};
}

}  // namespace sv::lights
