// The lights' sizes and weights in lanes (lights/splat_sizes.h) against one light at a time, on
// every SIMD target the build generates, bit for bit: lights of every size from the minimum to the
// clamp's maximum and beyond it, dark ones, ones off every edge of the raster, stars, and lights
// within the depth bias of the eye.
#include "lights/splat_sizes.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <random>

#include "hwy/targets.h"

namespace sv::lights {
namespace {

// Bitwise equality of two floats (the lanes must give the reference's bits, not a near value).
bool same(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(SplatSizes, LanesEqualOneLightAtATimeOnEveryTarget) {
  SizeLaws laws;
  laws.minSize = 1.5f, laws.maxSize = 12;
  laws.width = 640, laws.height = 360;
  laws.depthBias = 0.5f;
  laws.m22 = 1.0002f, laws.m32 = -0.20002f;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> position(-30, 670), unit(0, 1), depth(0.1f, 900);
  std::uniform_real_distribution<float> logEnergy(-7, 4);  // Φ from 10⁻⁷ (dark) to 10⁴ (clamped)
  std::uniform_int_distribution<int> lights(1, SizeBatch::kLights);
  int drawn = 0, large = 0, kept = 0;
  for (int round = 0; round < 400; ++round) {
    SizeBatch in{};
    const int count = lights(rng);
    for (int i = 0; i < count; ++i) {
      in.x[i] = position(rng), in.y[i] = position(rng) * 0.55f;
      in.energy[i] = std::pow(10.0f, logEnergy(rng));
      in.r[i] = unit(rng), in.g[i] = unit(rng), in.b[i] = round % 7 == 0 ? 0 : unit(rng);
      const float pick = unit(rng);
      in.eyeDepth[i] = pick < 0.1f ? 0 : pick < 0.2f ? 0.3f * unit(rng) : depth(rng);
    }
    SizeBatch want = in;
    for (int i = 0; i < count; ++i) sizeSplat(laws, want, i);
    for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
      hwy::SetSupportedTargetsForTest(target);
      SizeBatch got = in;
      sizeSplats(laws, count, got);
      for (int i = 0; i < count; ++i) {
        SCOPED_TRACE(testing::Message() << hwy::TargetName(target) << ", light " << i
                                        << " of round " << round << ", energy " << in.energy[i]);
        ASSERT_EQ(got.drawn[i], want.drawn[i]);
        if (!want.drawn[i]) continue;
        EXPECT_TRUE(same(got.radius[i], want.radius[i]));
        EXPECT_TRUE(same(got.red[i], want.red[i]) && same(got.green[i], want.green[i]) &&
                    same(got.blue[i], want.blue[i]))
            << got.red[i] << " against " << want.red[i];
        EXPECT_TRUE(same(got.frontDepth[i], want.frontDepth[i]));
        EXPECT_EQ(got.firstX[i], want.firstX[i]);
        EXPECT_EQ(got.firstY[i], want.firstY[i]);
        EXPECT_EQ(got.spanX[i], want.spanX[i]);
        EXPECT_EQ(got.spanY[i], want.spanY[i]);
        for (int k = 0; k < 4; ++k)
          EXPECT_TRUE(same(got.kx[k][i], want.kx[k][i]) && same(got.ky[k][i], want.ky[k][i]));
      }
    }
    hwy::SetSupportedTargetsForTest(0);
    for (int i = 0; i < count; ++i) {
      drawn += want.drawn[i];
      large += want.drawn[i] && want.radius[i] > 1.5f;
      kept += want.drawn[i] && want.spanX[i] <= 4 && want.spanY[i] <= 4;
    }
  }
  // The inputs reach every case: drawn and culled, small and large, weights kept and not.
  EXPECT_GT(drawn, 300);
  EXPECT_GT(large, 100);
  EXPECT_GT(kept, 100);
  EXPECT_GT(drawn - kept, 50);
}

}  // namespace
}  // namespace sv::lights
