// The pixel-shading stage on its own (src/shade): fog at range 0 and far away, the level of detail
// against texture::pixelFootprint, and unused attributes left unread.
#include <gtest/gtest.h>

#include <cmath>

#include "shade/shading.h"
#include "texture/footprint.h"
#include "texture/texture.h"

namespace sv::shade {
namespace {

Fragments flatFragments(float r, float g, float b) {
  Fragments f;
  f.count = kMaxFragments;
  for (int i = 0; i < kMaxFragments; ++i) {
    f.q[i] = 0.5f;  // w = 2
    f.color[0][i] = r;
    f.color[1][i] = g;
    f.color[2][i] = b;
    for (float* a : f.attribute) a[i] = 0;
  }
  return f;
}

TEST(Fog, RangeZeroKeepsTheSurfaceAndGreatRangeGivesTheFogColour) {
  MaterialShading m;
  Environment env;
  env.fog = true;
  env.fogColor = {0.1f, 0.2f, 0.9f};
  env.fogBeta = 0.3f;
  Fragments f = flatFragments(0.8f, 0.6f, 0.4f);
  // Lane 0 at the eye (range 0), lane 1 at range 10 (eye position/w = (0, 0, −10)/2), lane 2
  // at range 10^6.
  f.attribute[kEyeZ][1] = -5;
  f.attribute[kEyeZ][2] = -5e5f;
  float out[4][kMaxFragments];
  shadeFragments(m, env, f, out);
  EXPECT_FLOAT_EQ(out[0][0], 0.8f);
  EXPECT_FLOAT_EQ(out[1][0], 0.6f);
  EXPECT_FLOAT_EQ(out[2][0], 0.4f);
  const float k = fogFactor(0.3f, 10);  // 2^(−3) = 1/8
  EXPECT_NEAR(k, 0.125f, 1e-6f);
  EXPECT_NEAR(out[0][1], 0.8f * k + 0.1f * (1 - k), 1e-5f);
  EXPECT_NEAR(out[2][1], 0.4f * k + 0.9f * (1 - k), 1e-5f);
  EXPECT_FLOAT_EQ(out[0][2], 0.1f);
  EXPECT_FLOAT_EQ(out[1][2], 0.2f);
  EXPECT_FLOAT_EQ(out[2][2], 0.9f);
  EXPECT_FLOAT_EQ(out[3][2], 1.0f);
}

// A 64 × 64 texture of single-texel black and white stripes in x: level 0 holds 0 and 1 only,
// every coarser level ½ (the filter averages neighbours).
texture::Texture stripes() {
  texture::Level level;
  level.width = level.height = 64;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const uint16_t v = x % 2 ? 65535 : 0;
      level.texels.push_back({v, v, v, 65535});
    }
  return texture::Texture(level, texture::Wrap::repeat, texture::Wrap::repeat);
}

TEST(LevelOfDetail, NearestPicksTheLevelPixelFootprintNames) {
  const texture::Texture tex = stripes();
  MaterialShading m;
  m.texture = &tex;
  m.filter = texture::Filter::nearest;
  Environment env;
  // Per lane a different scale s (texels per pixel along x): U = s·x/64 at q = 1 (w = 1); the
  // level is ⌊lod + ½⌋ with lod = log2(s), so level 0 (black or white) below s = √2, level ≥ 1
  // (grey) above.
  for (double s : {1.0, 1.3, 1.45, 1.6, 2.5, 3.0}) {
    Fragments f = flatFragments(1, 1, 1);
    f.qdx = f.qdy = 0;
    f.udx = float(s / 64);
    f.udy = 0;
    f.vdx = 0;
    f.vdy = float(1.0 / 64);
    for (int i = 0; i < kMaxFragments; ++i) {
      f.q[i] = 1;
      f.attribute[kU][i] = float((i * 2 + 0.25) / 64);  // a texel centre region, away from edges
      f.attribute[kV][i] = 0.5f;
    }
    const texture::Footprint fp = texture::pixelFootprint({f.attribute[kU][0], f.udx, f.udy},
                                                          {0.5, f.vdx, f.vdy}, {1, 0, 0}, 64, 64);
    ASSERT_NEAR(fp.lod, std::log2(s), 1e-6);
    float out[4][kMaxFragments];
    shadeFragments(m, env, f, out);
    const bool level0 = std::floor(fp.lod + 0.5) == 0;
    for (int i = 0; i < kMaxFragments; ++i) {
      if (level0)
        EXPECT_TRUE(out[0][i] == 0 || out[0][i] == 1) << "s " << s << " lane " << i << ": " << out[0][i];
      else
        EXPECT_NEAR(out[0][i], 0.5, 0.01) << "s " << s << " lane " << i;
    }
  }
}

}  // namespace
}  // namespace sv::shade
