// The Earth model: WGS 84, and the one conversion every geodetic position in synthvis goes through
// (docs/terrain.md, "Geographic tables"; docs/ig.md, "Coordinates") — a geographic height table's
// samples, a draped image's bounds and the IG's entities alike, so that they agree wherever they
// are.
//
// Based on: NIMA TR8350.2 (WGS 84: a = 6 378 137 m, 1/f = 298.257 223 563); the ellipsoid's
// radii of curvature M (meridian) and N (prime vertical) from any geodesy text (Torge, Geodesy,
// §4.1). The map is the equirectangular projection on the ellipsoid with its standard parallel at
// the frame's origin: east = N(φ₀)·cos φ₀·Δλ, north = M(φ₀)·Δφ — true to scale at the origin
// along both axes, its grid regular in latitude and longitude (a geographic raster stays a
// regular table). Heights are along the base's normal: a plane through the origin, or (curved)
// the sphere of the ellipsoid's Gaussian radius √(M·N) at φ₀ through it, the map carried onto it
// by central projection (onBase).
#pragma once

#include <cmath>
#include <numbers>

#include "synthvis/math.h"

namespace sv {

inline constexpr double kWgs84SemiMajor = 6378137.0;                           // a, metres
inline constexpr double kWgs84Flattening = 1 / 298.257223563;                  // f
inline constexpr double kWgs84E2 = kWgs84Flattening * (2 - kWgs84Flattening);  // e² = f(2 − f)

// The radii of curvature at geodetic latitude `lat` (radians): along the meridian, and of the
// prime vertical (M = a(1 − e²)/w³, N = a/w, w = √(1 − e² sin² φ)).
inline double meridianRadius(double lat) {
  const double s = std::sin(lat), w = std::sqrt(1 - kWgs84E2 * s * s);
  return kWgs84SemiMajor * (1 - kWgs84E2) / (w * w * w);
}
inline double primeVerticalRadius(double lat) {
  const double s = std::sin(lat);
  return kWgs84SemiMajor / std::sqrt(1 - kWgs84E2 * s * s);
}
// The sphere that fits the ellipsoid best at `lat` (radians): √(M·N).
inline double gaussianRadius(double lat) {
  return std::sqrt(meridianRadius(lat) * primeVerticalRadius(lat));
}

// A point of the base's tangent plane at the origin — world x (east) and z (south), metres — at
// height `h` above the base, in the world (y up): the plane y = 0 (`radius` 0), or the sphere of
// `radius` through the origin, centre (0, −radius, 0), reached by central (gnomonic) projection
// from its centre with h along its radius (SPEC §11: heights over a base surface).
inline Vec3d onBase(double x, double z, double h, double radius) {
  if (radius <= 0) return {x, h, z};
  const Vec3d d = normalize(Vec3d{x, radius, z});
  return Vec3d{0, -radius, 0} + d * (radius + h);
}

// A geodetic position: latitude and longitude in degrees, altitude in metres above the ellipsoid.
struct GeoPoint {
  double lat = 0, lon = 0, alt = 0;
};

// A database's frame on the Earth: the geodetic position of the world origin, and whether the
// ground curves (the base above). Its map metres are east and north of the origin.
class GeoFrame {
 public:
  GeoFrame() : GeoFrame(GeoPoint{}) {}
  explicit GeoFrame(GeoPoint origin, bool curved = false)
      : origin_(origin),
        east_(primeVerticalRadius(origin.lat * kRad) * std::cos(origin.lat * kRad) * kRad),
        north_(meridianRadius(origin.lat * kRad) * kRad),
        radius_(curved ? gaussianRadius(origin.lat * kRad) : 0) {}

  const GeoPoint& origin() const { return origin_; }
  // The base's radius: 0 for the plane, else the Gaussian sphere's.
  double baseRadius() const { return radius_; }
  // Metres east and north of the origin per degree of longitude and of latitude.
  double metresPerDegreeEast() const { return east_; }
  double metresPerDegreeNorth() const { return north_; }

  // Map metres of a latitude and longitude (degrees), and back.
  double east(double lon) const { return (lon - origin_.lon) * east_; }
  double north(double lat) const { return (lat - origin_.lat) * north_; }
  double lon(double east) const { return origin_.lon + east / east_; }
  double lat(double north) const { return origin_.lat + north / north_; }

  // The world position (+x east, +y up, −z north) of a geodetic point, and back.
  Vec3d toWorld(const GeoPoint& p) const {
    return onBase(east(p.lon), -north(p.lat), p.alt - origin_.alt, radius_);
  }
  GeoPoint toGeodetic(Vec3d w) const {
    if (radius_ <= 0) return {lat(-w.z), lon(w.x), w.y + origin_.alt};
    // The inverse of onBase: the line from the centre through w meets the tangent plane.
    const Vec3d d{w.x, w.y + radius_, w.z};
    const double k = radius_ / d.y;
    return {lat(-d.z * k), lon(d.x * k), length(d) - radius_ + origin_.alt};
  }

 private:
  static constexpr double kRad = std::numbers::pi / 180;
  GeoPoint origin_;
  double east_, north_, radius_;
};

}  // namespace sv
