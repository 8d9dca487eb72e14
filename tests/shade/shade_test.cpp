// The pixel-shading stage on its own (src/shade): fog at range 0 and far away, the level of detail
// against texture::pixelFootprint, and the same bits on every SIMD target.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "hwy/targets.h"
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
        EXPECT_TRUE(out[0][i] == 0 || out[0][i] == 1)
            << "s " << s << " lane " << i << ": " << out[0][i];
      else
        EXPECT_NEAR(out[0][i], 0.5, 0.01) << "s " << s << " lane " << i;
    }
  }
}

// Textured (trilinear and anisotropic), Phong-lit with a specular term and a point light, fogged,
// translucent fragments shade to the same bits on every compiled SIMD target, in one step and in
// two (docs/ARCHITECTURE.md promises images that do not depend on the CPU): the stage uses no
// fused multiply-add and its own exp2/log2.
TEST(Shading, SameBitsOnEverySimdTarget) {
  texture::Level level;
  level.width = 48;
  level.height = 40;
  std::mt19937 rng(5);
  for (int i = 0; i < level.width * level.height; ++i)
    level.texels.push_back({uint16_t(rng()), uint16_t(rng()), uint16_t(rng()), uint16_t(rng())});
  const texture::Texture tex(level, texture::Wrap::repeat, texture::Wrap::mirror);
  Environment env;
  env.lightOn = true;
  env.toLight = normalize(Vec3{0.3f, 0.8f, 0.52f});
  env.points.push_back({{2, 1, -4}, {0.9f, 0.7f, 0.5f}});
  env.fog = true;
  env.fogColor = {0.6f, 0.65f, 0.7f};
  env.fogBeta = 0.07f;
  std::uniform_real_distribution<float> u(0, 1);
  std::vector<Fragments> inputs;
  for (int round = 0; round < 24; ++round) {
    Fragments f;
    f.count = 1 + round % kMaxFragments;
    for (int i = 0; i < kMaxFragments; ++i) {
      f.q[i] = 0.02f + u(rng);
      for (auto& c : f.color) c[i] = u(rng) * f.q[i];
      for (float* a : f.attribute) a[i] = (u(rng) * 2 - 1) * f.q[i];
      f.attribute[kU][i] = u(rng) * 6 * f.q[i];
      f.attribute[kV][i] = (u(rng) * 6 - 3) * f.q[i];
      f.attribute[kEyeZ][i] = -(0.1f + u(rng) * 60) * f.q[i];
      f.attribute[kAlpha][i] = u(rng) * f.q[i];
    }
    f.qdx = (u(rng) - 0.5f) * 1e-3f;
    f.qdy = (u(rng) - 0.5f) * 1e-3f;
    f.udx = u(rng) * 0.05f;
    f.udy = (u(rng) - 0.5f) * 0.02f;
    f.vdx = (u(rng) - 0.5f) * 0.02f;
    f.vdy = u(rng) * 0.2f;
    inputs.push_back(f);
  }
  std::vector<MaterialShading> materials(3);
  for (MaterialShading& m : materials) {
    m.texture = &tex;
    m.phong = true;
    m.specular = 0.6f;
    m.shininess = 21;
    m.alpha = AlphaUse::blend;
  }
  materials[1].anisotropic = true;
  materials[2].filter = texture::Filter::trilinearThreePoint;
  materials[2].twoSided = true;
  materials[2].alpha = AlphaUse::mask;

  std::vector<float> reference;
  int targets = 0;
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    std::vector<float> result;
    for (const MaterialShading& m : materials)
      for (const Fragments& f : inputs) {
        float out[4][kMaxFragments], twoStep[4][kMaxFragments];
        shadeFragments(m, env, f, out);
        TexCoords tc;
        textureCoordinates(m, f, tc);
        shadeFragments(m, env, f, tc, twoStep);
        for (int ch = 0; ch < 4; ++ch)
          for (int i = 0; i < f.count; ++i) {
            ASSERT_EQ(0, std::memcmp(&out[ch][i], &twoStep[ch][i], sizeof(float)))
                << hwy::TargetName(target) << " channel " << ch << " fragment " << i;
            result.push_back(out[ch][i]);
          }
      }
    if (reference.empty()) {
      reference = result;
    } else {
      ASSERT_EQ(result.size(), reference.size());
      for (size_t i = 0; i < result.size(); ++i)
        ASSERT_EQ(0, std::memcmp(&result[i], &reference[i], sizeof(float)))
            << hwy::TargetName(target) << " value " << i << ": " << result[i] << " vs "
            << reference[i];
    }
    ++targets;
  }
  hwy::SetSupportedTargetsForTest(0);
  EXPECT_GE(targets, 1);
}

}  // namespace
}  // namespace sv::shade
