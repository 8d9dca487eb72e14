// The simulated viewer (display/viewer.h): the demo rig's projectors, each showing flat grey
// blended by its alpha map, add up to that grey across the screen — overlaps included — and
// nothing beyond the screen's edges; a projector's image lands where its pixels light the screen.
#include "display/viewer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "display/blend.h"

namespace sv::display {
namespace {

TEST(Viewer, BlendedProjectorsOfFlatGreyAddUpToItAcrossTheOverlaps) {
  const CylinderRig rig = threeProjectorCylinder(3, 10, 320, 200);
  const std::vector<BlendMap> alpha = cylinderAlphaMaps(rig, 10, 160, 100);
  std::vector<std::vector<uint16_t>> frames;
  std::vector<const uint16_t*> images;
  for (size_t i = 0; i < 3; ++i) {
    frames.emplace_back(size_t(320) * 200 * 3, uint16_t(40000));
    MpcdiRegion r;
    r.xResolution = 320;
    r.yResolution = 200;
    r.alpha = alpha[i];
    applyBlend(blendWeights(r), frames.back().data());
  }
  for (const auto& f : frames) images.push_back(f.data());
  PanoramaView view;
  view.width = 400;
  view.height = 100;
  const ResampledImage p = viewerPanorama(rig.screen, rig.eye, rig.projectors, images, view);
  ASSERT_EQ(p.width, 400);
  // The screen spans azimuth ±96° and ±1.2 m at a radius of 3 m (±21.8°): the panorama's outer
  // columns and rows miss it.
  EXPECT_GT(p.invalid, 0);
  double worst = 0;
  int64_t onScreen = 0;
  for (int y = 0; y < p.height; ++y)
    for (int x = 0; x < p.width; ++x) {
      const double azimuth = -100 + (x + 0.5) / 400 * 200;
      const double elevation = 25 - (y + 0.5) / 100 * 50;
      const uint16_t v = p.rgb[(size_t(y) * 400 + size_t(x)) * 3];
      // The projectors stand above and behind the eye: their images' upper and lower edges curve
      // across the screen, and all of them light it fully within ±12° of the eye's height.
      const bool inside = std::abs(azimuth) < 94 && std::abs(elevation) < 12;
      const bool beyond = std::abs(azimuth) > 97 || std::abs(elevation) > 22.5;
      if (beyond) {
        EXPECT_EQ(v, 0) << x << "," << y;
      }
      if (!inside) continue;
      ++onScreen;
      worst = std::max(worst, std::abs(v / 40000.0 - 1));
    }
  EXPECT_GT(onScreen, 370 * 45);
  EXPECT_LT(worst, 0.004);  // the alpha maps' bilinear sampling, and the projector pixels' own
  std::printf("blended grey on the screen: within %.4f of its value\n", worst);
}

TEST(Viewer, AProjectorsImageLandsWhereItsPixelsLightTheScreen) {
  // Only the centre projector, its left half white: the viewer sees white left of the projector's
  // centre column's azimuth and black right of it.
  const CylinderRig rig = threeProjectorCylinder(3, 10, 320, 200);
  std::vector<uint16_t> left(size_t(320) * 200 * 3, 0);
  for (int y = 0; y < 200; ++y)
    for (int x = 0; x < 160; ++x)
      for (int c = 0; c < 3; ++c) left[(size_t(y) * 320 + size_t(x)) * 3 + size_t(c)] = 65535;
  const std::vector<uint16_t> black(left.size(), 0);
  PanoramaView view;
  view.width = 400;
  view.height = 100;
  const ResampledImage p = viewerPanorama(rig.screen, rig.eye, rig.projectors,
                                          {black.data(), left.data(), black.data()}, view);
  // The centre column of the centre projector lights azimuth 0 (its yaw): white just left of it,
  // black just right, on the row at the eye's height.
  const int row = 50;
  EXPECT_GT(p.rgb[(size_t(row) * 400 + 196) * 3], 60000);
  EXPECT_LT(p.rgb[(size_t(row) * 400 + 203) * 3], 5000);
  EXPECT_EQ(p.rgb[(size_t(row) * 400 + 100) * 3], 0);      // azimuth −50°: the left projector's
  EXPECT_EQ(p.rgb[(size_t(row) * 400 + 140) * 3], 65535);  // −30°: the centre's left half
}

}  // namespace
}  // namespace sv::display
