// What a viewer at the eye sees on a screen lit by projectors — issue 34's simulated viewer, who
// reconstructs the scene from the projectors' pre-distorted, edge-blended images: straight lines
// come out straight and continuous across the projectors' seams, and the blended overlaps as bright
// as the rest, exactly when the correction and the blend are right.
#pragma once

#include <cstdint>
#include <vector>

#include "display/geometry.h"
#include "display/resample.h"
#include "display/subfrustum.h"

namespace sv::display {

// A panorama around the eye: pixel columns even in azimuth (from −z toward +x, as Screen's), rows
// even in elevation, top row highest; centres at +0.5.
struct PanoramaView {
  double minAzimuthDegrees = -100, maxAzimuthDegrees = 100;
  double minElevationDegrees = -25, maxElevationDegrees = 25;
  int width = 1600, height = 400;
};

// Where direction `d` (any length) lies in the panorama: a continuous pixel (centres at +0.5),
// beyond [0, width) × [0, height) when the view does not hold it.
struct PanoramaPoint {
  double x = 0, y = 0;
};
PanoramaPoint panoramaPoint(const PanoramaView& view, Vec3d d);

// The panorama that holds every valid direction of `tables` (the field a display's projectors
// cover, seen from its eye), `pixelDegrees` a pixel in azimuth and elevation. A field wider than
// 360° in azimuth is not a panorama: the caller's displays span less (a dome's zenith would need
// another map, and has none here).
PanoramaView panoramaOf(const std::vector<const DirectionTable*>& tables, double pixelDegrees);

// Each panorama pixel: the screen point the eye sees in its centre's direction, and there the sum
// over the projectors of each one's image (`images[i]`: linear-light 16-bit RGB of
// projectors[i].width × height pixels, 3 values a pixel, rows top first — blended already) at the
// point of its image that lights the screen point, `filter`ed; clamped to 65 535. A white
// diffuse screen and projectors of equal brightness, as an edge blend assumes. Pixels whose
// direction misses the screen are black and counted in `invalid`; `outside` counts those that no
// projector lights.
ResampledImage viewerPanorama(const Screen& screen, Vec3 eye,
                              const std::vector<Projector>& projectors,
                              const std::vector<const uint16_t*>& images, const PanoramaView& view,
                              ResampleFilter filter = ResampleFilter::bilinear);

}  // namespace sv::display
