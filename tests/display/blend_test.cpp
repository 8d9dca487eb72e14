// Blend maps: bilinear from the map's resolution to the region's, alpha's embedded gamma, the
// blend applied in linear light, and the demo rig's ramps summing to one across each overlap.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "display/blend.h"

namespace sv::display {
namespace {

TEST(Blend, MapIsBilinearBetweenSampleCentres) {
  BlendMap m;
  m.width = 2;
  m.height = 1;
  m.bitDepth = 16;
  m.codes = {0, 65535};
  // On a 4 × 1 region the samples sit at x = 1 and x = 3.
  EXPECT_DOUBLE_EQ(sampleBlend(m, 4, 1, 1, 0.5), 0);
  EXPECT_DOUBLE_EQ(sampleBlend(m, 4, 1, 3, 0.5), 1);
  EXPECT_DOUBLE_EQ(sampleBlend(m, 4, 1, 2, 0.5), 0.5);
  EXPECT_DOUBLE_EQ(sampleBlend(m, 4, 1, 2.5, 0.5), 0.75);
  EXPECT_DOUBLE_EQ(sampleBlend(m, 4, 1, 0.2, 0.5), 0);  // beyond the outer centres: the edge
  EXPECT_DOUBLE_EQ(sampleBlend(m, 4, 1, 3.9, 0.5), 1);
}

TEST(Blend, WeightsApplyTheEmbeddedGammaAndBeta) {
  MpcdiRegion r;
  r.xResolution = 2;
  r.yResolution = 1;
  BlendMap a;
  a.width = 2;
  a.height = 1;
  a.bitDepth = 8;
  a.codes = {255, 128};
  r.alpha = a;
  r.alphaGammaEmbedded = 2;
  BlendMap b = a;
  b.codes = {0, 51};
  r.beta = b;
  const BlendWeights w = blendWeights(r);
  EXPECT_FLOAT_EQ(w.alpha[0], 1);
  EXPECT_FLOAT_EQ(w.alpha[1], float((128.0 / 255) * (128.0 / 255)));
  EXPECT_FLOAT_EQ(w.beta[0], 0);
  EXPECT_FLOAT_EQ(w.beta[1], 0.2f);
  // No maps: alpha 1, beta 0.
  r.alpha.reset();
  r.beta.reset();
  const BlendWeights none = blendWeights(r);
  EXPECT_EQ(none.alpha, (std::vector<float>{1, 1}));
  EXPECT_EQ(none.beta, (std::vector<float>{0, 0}));
}

TEST(Blend, AppliedInLinearLight) {
  BlendWeights w;
  w.width = 3;
  w.height = 1;
  w.alpha = {0.5f, 0.25f, 1};
  w.beta = {0, 0.1f, 0.5f};
  uint16_t rgb[9] = {1000, 65535, 0, 40000, 4, 65535, 65535, 60000, 1};
  applyBlend(w, rgb);
  // value·alpha + beta·65535, rounded, at most 65535.
  EXPECT_EQ(rgb[0], 500);
  EXPECT_EQ(rgb[1], 32768);  // 32767.5 rounds to even
  EXPECT_EQ(rgb[2], 0);
  EXPECT_EQ(rgb[3], uint16_t(std::nearbyint(40000 * 0.25f + 0.1f * 65535)));
  EXPECT_EQ(rgb[4], uint16_t(std::nearbyint(4 * 0.25f + 0.1f * 65535)));
  EXPECT_EQ(rgb[6], 65535);  // clamped
  EXPECT_EQ(rgb[8], uint16_t(std::nearbyint(1 + 0.5f * 65535)));
  // A negative weight (a hand-made BlendWeights) gives black, not a wrapped value.
  BlendWeights negative;
  negative.width = negative.height = 1;
  negative.alpha = {-0.5f};
  negative.beta = {0};
  uint16_t one[3] = {1000, 2000, 3000};
  applyBlend(negative, one);
  EXPECT_EQ(one[0], 0);
  EXPECT_EQ(one[2], 0);
}

// Where projector `p` shows eye-frame point `q`: its pinhole inverted (independent of
// viewOfPixel's forward rays).
void pixelOf(const Projector& p, Vec3 q, double& px, double& py) {
  const Rotation r = rotationOf(p.orientation);
  const double d[3] = {double(q.x) - p.position.x, double(q.y) - p.position.y,
                       double(q.z) - p.position.z};
  double l[3];
  for (int i = 0; i < 3; ++i) l[i] = r.m[0][i] * d[0] + r.m[1][i] * d[1] + r.m[2][i] * d[2];
  const double k = std::numbers::pi / 180;
  const double tl = std::tan(p.lens.leftDegrees * k), tr = std::tan(p.lens.rightDegrees * k);
  const double td = std::tan(p.lens.downDegrees * k), tu = std::tan(p.lens.upDegrees * k);
  px = (l[0] / -l[2] - tl) / (tr - tl) * p.width;
  py = (tu - l[1] / -l[2]) / (tu - td) * p.height;
}

TEST(Blend, RampsAcrossEachOverlapSumToOneInLinearLight) {
  const double overlap = 10;
  const int w = 320, h = 200;
  const CylinderRig rig = threeProjectorCylinder(3, overlap, w, h);
  const std::vector<BlendMap> maps = cylinderAlphaMaps(rig, overlap, w / 2, h / 2);
  ASSERT_EQ(maps.size(), 3u);
  const uint16_t light = 40000;  // a flat grey frame on every projector, linear
  for (int i = 0; i < 2; ++i) {
    MpcdiRegion left;
    left.xResolution = w;
    left.yResolution = h;
    left.alpha = maps[size_t(i)];
    const BlendWeights wl = blendWeights(left);
    std::vector<uint16_t> frame(size_t(w) * h * 3, light);
    applyBlend(wl, frame.data());
    int inOverlap = 0;
    double worst = 0;
    for (int y = 0; y < h; y += 7)
      for (int x = 0; x < w; ++x) {
        const PixelView v = viewOfPixel(rig.geometry(i), x + 0.5, y + 0.5);
        ASSERT_TRUE(v.valid);
        const double azimuth = std::atan2(v.screenPoint.x, -v.screenPoint.z) * 180 / std::numbers::pi;
        const double a0 = wl.alpha[size_t(y) * w + size_t(x)];
        if (azimuth < -30 + 60 * i - overlap / 2) {
          // Short of this overlap: alone, once past its overlap with its own left neighbour.
          if (i == 0 || azimuth > -90 + 60 * i + overlap / 2) {
            EXPECT_NEAR(a0, 1, 1e-3) << azimuth;  // a map sample across the edge may weigh in
          }
          continue;
        }
        // In the overlap: the right projector's pixel lighting the same point.
        double px, py;
        pixelOf(rig.projectors[size_t(i) + 1], v.screenPoint, px, py);
        // The other projector covers the overlap's azimuths; near the top and bottom corners
        // its image bows away, and the point is lit by the left projector alone.
        ASSERT_TRUE(px > -1 && px < w + 1) << px;
        if (!(px > 0 && px < w && py > 0 && py < h)) continue;
        const double a1 = sampleBlend(maps[size_t(i) + 1], w, h, px, py);
        ++inOverlap;
        worst = std::max(worst, std::fabs(a0 + a1 - 1));
        // The light both throw at the point, each blended in linear light, adds to the frame's.
        const double sum = frame[(size_t(y) * w + size_t(x)) * 3] + std::nearbyint(light * a1);
        EXPECT_NEAR(sum, light, 0.003 * light);
        // Halfway across, each carries half.
        if (std::fabs(azimuth - (-30 + 60 * i)) < 0.05) {
          EXPECT_NEAR(a0, 0.5, 0.01);
        }
      }
    EXPECT_GT(inOverlap, 100);
    EXPECT_LT(worst, 1e-3) << "overlap " << i;  // 6.1e-4 seen: the maps' bilinear rounding
  }
}

}  // namespace
}  // namespace sv::display
