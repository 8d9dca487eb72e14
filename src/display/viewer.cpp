#include "display/viewer.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/check.h"
#include "core/quadric.h"

namespace sv::display {

PanoramaPoint panoramaPoint(const PanoramaView& view, Vec3d d) {
  constexpr double kToDegrees = 180 / std::numbers::pi;
  // Azimuth from −z toward +x, elevation from the horizontal (the convention of Screen's).
  const double azimuth = std::atan2(d.x, -d.z) * kToDegrees;
  const double elevation = std::atan2(d.y, std::hypot(d.x, d.z)) * kToDegrees;
  return {(azimuth - view.minAzimuthDegrees) / (view.maxAzimuthDegrees - view.minAzimuthDegrees) *
              view.width,
          (view.maxElevationDegrees - elevation) /
              (view.maxElevationDegrees - view.minElevationDegrees) * view.height};
}

PanoramaView panoramaOf(const std::vector<const DirectionTable*>& tables, double pixelDegrees) {
  SV_CHECK(pixelDegrees > 0);
  constexpr double kToDegrees = 180 / std::numbers::pi;
  double az0 = 180, az1 = -180, el0 = 90, el1 = -90;
  for (const DirectionTable* t : tables)
    for (size_t i = 0; i < t->directions.size(); ++i) {
      if (!t->valid[i]) continue;
      const Vec3d& d = t->directions[i];
      const double azimuth = std::atan2(d.x, -d.z) * kToDegrees;
      const double elevation = std::atan2(d.y, std::hypot(d.x, d.z)) * kToDegrees;
      az0 = std::min(az0, azimuth), az1 = std::max(az1, azimuth);
      el0 = std::min(el0, elevation), el1 = std::max(el1, elevation);
    }
  PanoramaView v;
  if (az0 > az1) return v;  // no valid pixel: the default view
  // Whole pixels, the field centred in them.
  v.width = std::max(1, int(std::ceil((az1 - az0) / pixelDegrees)));
  v.height = std::max(1, int(std::ceil((el1 - el0) / pixelDegrees)));
  const double az = 0.5 * (az0 + az1), el = 0.5 * (el0 + el1);
  v.minAzimuthDegrees = az - 0.5 * v.width * pixelDegrees;
  v.maxAzimuthDegrees = az + 0.5 * v.width * pixelDegrees;
  v.minElevationDegrees = el - 0.5 * v.height * pixelDegrees;
  v.maxElevationDegrees = el + 0.5 * v.height * pixelDegrees;
  return v;
}

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
