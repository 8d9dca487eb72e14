#include "texture/footprint.h"

#include <algorithm>
#include <cmath>

namespace sv::texture {

Footprint pixelFootprint(const LinearAt& U, const LinearAt& V, const LinearAt& Q, double texelsU,
                         double texelsV) {
  // Step 1: the Jacobian of (u, v) = (U, V)/Q, in texels per pixel.
  const double q2 = Q.value * Q.value;
  const double a = texelsU * (U.dx * Q.value - U.value * Q.dx) / q2;  // ∂u/∂x
  const double b = texelsU * (U.dy * Q.value - U.value * Q.dy) / q2;  // ∂u/∂y
  const double c = texelsV * (V.dx * Q.value - V.value * Q.dx) / q2;  // ∂v/∂x
  const double d = texelsV * (V.dy * Q.value - V.value * Q.dy) / q2;  // ∂v/∂y
  // Step 2: its singular values, from the eigenvalues of J·Jᵀ = [p r; r s].
  const double p = a * a + b * b, s = c * c + d * d, r = a * c + b * d;
  const double mean = 0.5 * (p + s), spread = std::sqrt(0.25 * (p - s) * (p - s) + r * r);
  Footprint f;
  f.major = std::sqrt(mean + spread);
  f.minor = std::sqrt(std::max(0.0, mean - spread));
  // Step 3: the major axis — the eigenvector of the larger eigenvalue (any axis if isotropic).
  const double ex = r, ey = mean + spread - p;
  const double len = std::hypot(ex, ey);
  if (len > 1e-12 * (mean + spread)) {
    f.axisX = ex / len;
    f.axisY = ey / len;
  } else if (p < s) {
    f.axisX = 0;
    f.axisY = 1;
  }
  f.lod = std::max(0.0, std::log2(f.major));
  return f;
}

double seedFootprint(double nx, double ny, double nz, double d, double deltaX, double deltaY,
                     double x0, double y0) {
  const double delta = std::max(deltaX, deltaY);
  const double dot = nx * deltaX * x0 + ny * deltaY * y0 - nz;  // N · ray, the ray (ΔxX₀, ΔyY₀, −1)
  return 2 * delta * d / (dot * dot);
}

}  // namespace sv::texture
