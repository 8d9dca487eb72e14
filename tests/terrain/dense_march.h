// The terrain tests' reference: a ray's first crossing of a caster's surface by brute force.
#pragma once

#include <algorithm>
#include <cmath>

#include "terrain/caster.h"

namespace sv::terrain::tests {

// The first crossing by a march of 1/256 cell, refined by bisection: the reference.
inline double denseMarch(const Caster& c, Vec3d o, Vec3d d, double s0, double s1) {
  const Caster::MapPoint a = c.toMap(o), b = c.toMap(o + d);
  const double speed = std::max(std::hypot(b.gx - a.gx, b.gy - a.gy), 1e-9);
  const double step = 1.0 / 256 / speed;
  auto f = [&](double s) {
    const Caster::MapPoint m = c.toMap(o + d * s);
    const double h = c.surface(m.gx, m.gy);
    return std::isnan(h) ? 1e300 : m.h - h;
  };
  double prev = s0;
  for (double s = s0; s <= s1; s += step) {
    if (f(s) <= 0) {
      double lo = prev, hi = s;
      for (int i = 0; i < 60; ++i) {
        const double m = 0.5 * (lo + hi);
        (f(m) <= 0 ? hi : lo) = m;
      }
      return hi;
    }
    prev = s;
  }
  return NAN;
}

}  // namespace sv::terrain::tests
