// The terrain's per-pixel shading inputs in SIMD lanes (terrain/shade_lanes.h) against the
// geometry worked out by hand: a camera looking straight down on planes of known slope.
#include "terrain/shade_lanes.h"

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

namespace sv::terrain {
namespace {

// Straight down from 100 m: forward −y, right +x, up −z (north); a ray per raster point of a
// 640-pixel-wide window 1 unit wide at unit depth.
ShadeFrame downward() {
  ShadeFrame f;
  const float d0[3] = {-0.5f, -1, -0.375f}, dX[3] = {1.0f / 640, 0, 0}, dY[3] = {0, 0, 1.0f / 640};
  const float right[3] = {1, 0, 0}, up[3] = {0, 0, -1}, forward[3] = {0, -1, 0};
  for (int k = 0; k < 3; ++k) {
    f.d0[k] = d0[k], f.dX[k] = dX[k], f.dY[k] = dY[k];
    f.right[k] = right[k], f.up[k] = up[k], f.forward[k] = forward[k];
  }
  f.spacingU = 20, f.spacingV = 20, f.scale = 0.5f;
  f.image = true;
  f.perMetreX = f.perMetreY = 64;  // texels a metre
  f.texX = 20 * 64, f.texX0 = -0.5f, f.texY = 20 * 64, f.texY0 = 7.5f;
  return f;
}

// A plane of heights code = a·i + b·j (i east, j south) under pixel (px, py).
void planeAt(ShadeLanes& l, int lane, float px, float py, float a, float b) {
  l.px[lane] = px, l.py[lane] = py, l.s[lane] = 100;
  l.gx[lane] = 3.25f, l.gy[lane] = 7.5f;
  l.cellU[lane] = 0.25f, l.cellV[lane] = 0.5f;
  const float i = 3, j = 7;
  l.h00[lane] = a * i + b * j, l.h10[lane] = a * (i + 1) + b * j;
  l.h01[lane] = a * i + b * (j + 1), l.h11[lane] = a * (i + 1) + b * (j + 1);
  l.step[lane] = 1;
}

TEST(ShadeLanes, NormalsEyePositionsAndTexturesOfKnownPlanes) {
  const ShadeFrame f = downward();
  ShadeLanes l{};
  const float slopes[4][2] = {{0, 0}, {40, 0}, {0, -40}, {40, 40}};
  for (int lane = 0; lane < 16; ++lane)
    planeAt(l, lane, 10.5f + 37 * lane, 20.5f + 23 * lane, slopes[lane % 4][0],
            slopes[lane % 4][1]);
  shade::Fragments frag{};
  shade::TexCoords tc{};
  frag.count = 16;
  shadeLanes(f, l, frag, tc);
  for (int lane = 0; lane < 16; ++lane) {
    // Normal: (−∂h/∂east, 1, ∂h/∂north) with ∂h/∂east = a·scale/spacing, ∂h/∂north = −b·…
    const double se = slopes[lane % 4][0] * 0.5 / 20, sn = -slopes[lane % 4][1] * 0.5 / 20;
    const double len = std::sqrt(se * se + 1 + sn * sn);
    const double n[3] = {-se / len, 1 / len, sn / len};
    // Eye space: x = right (+x), y = up (−z), z = −forward (+y).
    EXPECT_NEAR(frag.attribute[shade::kNormalX][lane], n[0], 1e-6) << lane;
    EXPECT_NEAR(frag.attribute[shade::kNormalY][lane], -n[2], 1e-6) << lane;
    EXPECT_NEAR(frag.attribute[shade::kNormalZ][lane], n[1], 1e-6) << lane;
    const double dx = -0.5 + l.px[lane] / 640.0, dz = -0.375 + l.py[lane] / 640.0;
    EXPECT_NEAR(frag.attribute[shade::kEyeX][lane], 100 * dx, 1e-4);
    EXPECT_NEAR(frag.attribute[shade::kEyeY][lane], -100 * dz, 1e-4);
    EXPECT_NEAR(frag.attribute[shade::kEyeZ][lane], -100, 1e-4);
    EXPECT_NEAR(tc.x0[lane], 3.25 * 20 * 64 - 0.5, 1e-2);
    EXPECT_NEAR(tc.y0[lane], 7.5 * 20 * 64 + 7.5, 1e-2);
  }
  // On the flat plane a pixel is 100/640 m on the ground both ways: 10 texels, level log2 10.
  EXPECT_NEAR(tc.lod[0], std::log2(10.0), 1e-4);
  // Tilted planes stretch the footprint along their slope: a coarser level.
  EXPECT_GT(tc.lod[1], tc.lod[0] + 0.01);
  EXPECT_GT(tc.lod[3], tc.lod[1]);
}

TEST(ShadeLanes, MagnificationIsLevelZeroAndEveryTargetGivesTheSameBits) {
  ShadeFrame f = downward();
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(0, 1);
  ShadeLanes l{};
  for (int lane = 0; lane < 16; ++lane)
    planeAt(l, lane, 640 * u(rng), 480 * u(rng), 80 * u(rng) - 40, 80 * u(rng) - 40);
  std::vector<float> first;
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    for (const float perMetre : {64.0f, 0.5f}) {  // minified, magnified
      f.perMetreX = f.perMetreY = perMetre;
      shade::Fragments frag{};
      shade::TexCoords tc{};
      frag.count = 13;  // a part-filled batch
      shadeLanes(f, l, frag, tc);
      if (perMetre < 1) {
        for (int lane = 0; lane < 13; ++lane) EXPECT_EQ(tc.lod[lane], 0.0f);
      }
      std::vector<float> got(tc.lod, tc.lod + 13);
      for (int a = 0; a < geometry::kAttributeCount; ++a)
        got.insert(got.end(), frag.attribute[a], frag.attribute[a] + 13);
      got.insert(got.end(), tc.x0, tc.x0 + 13);
      if (first.size() < 2 * got.size()) {
        first.insert(first.end(), got.begin(), got.end());
        continue;
      }
      const size_t at = perMetre < 1 ? got.size() : 0;
      EXPECT_EQ(std::memcmp(got.data(), first.data() + at, got.size() * sizeof(float)), 0)
          << hwy::TargetName(target);
    }
  }
  hwy::SetSupportedTargetsForTest(0);
}

}  // namespace
}  // namespace sv::terrain
