#include "display/viewer.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/check.h"
#include "core/quadric.h"

namespace sv::display {

ResampledImage viewerPanorama(const Screen& screen, Vec3 eye,
                              const std::vector<Projector>& projectors,
                              const std::vector<const uint16_t*>& images, const PanoramaView& view,
                              ResampleFilter filter) {
  SV_CHECK(projectors.size() == images.size());
  constexpr double kToRadians = std::numbers::pi / 180;
  const int w = view.width, h = view.height;
  const size_t n = size_t(w) * size_t(h);
  ResampledImage out;
  out.width = w;
  out.height = h;
  out.rgb.assign(n * 3, 0);
  // The screen point of every panorama pixel, once.
  std::vector<Vec3d> points(n);
  std::vector<uint8_t> seen(n, 0);
  const Vec3d from{eye.x, eye.y, eye.z};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double azimuth = (view.minAzimuthDegrees +
                              (x + 0.5) / w * (view.maxAzimuthDegrees - view.minAzimuthDegrees)) *
                             kToRadians;
      const double elevation =
          (view.maxElevationDegrees -
           (y + 0.5) / h * (view.maxElevationDegrees - view.minElevationDegrees)) *
          kToRadians;
      const Vec3d d{std::cos(elevation) * std::sin(azimuth), std::sin(elevation),
                    -std::cos(elevation) * std::cos(azimuth)};
      const size_t i = size_t(y) * size_t(w) + size_t(x);
      if (const std::optional<Vec3d> p = screenPoint(screen, from, d)) points[i] = *p, seen[i] = 1;
    }
  std::vector<uint8_t> lit(n, 0);
  for (size_t k = 0; k < projectors.size(); ++k) {
    const Projector& p = projectors[k];
    // The directions from the projector to the screen points: where its image lights them.
    DirectionMap towards;
    towards.width = w;
    towards.height = h;
    towards.valid = seen;
    towards.directions.resize(n);
    for (size_t i = 0; i < n; ++i)
      if (seen[i])
        towards.directions[i] = {float(points[i].x - p.position.x),
                                 float(points[i].y - p.position.y),
                                 float(points[i].z - p.position.z)};
    const FlatView flat{p.orientation, p.lens, p.width, p.height};
    const ResampleWarp warp = resampleWarp(flat, towards);
    std::vector<uint16_t> light(3 * n);
    resampleRows(warp, images[k], filter, 0, h, light.data());
    for (size_t i = 0; i < n; ++i) {
      if (!seen[i]) continue;
      if (warp.lands(i)) lit[i] = 1;
      for (size_t c = 0; c < 3; ++c)  // black where this projector does not reach
        out.rgb[3 * i + c] =
            uint16_t(std::min<uint32_t>(65535, uint32_t(out.rgb[3 * i + c]) + light[3 * i + c]));
    }
  }
  for (size_t i = 0; i < n; ++i) {
    out.invalid += !seen[i];
    out.outside += seen[i] && !lit[i];
  }
  return out;
}

}  // namespace sv::display
