// Texture maps (SPEC §7): wrap modes, the seed's pyramid against a direct evaluation of its 3×3
// triangle filter, three-point interpolation against the seed's formulas at the corners, on the
// diagonal and at the centre, bilinear and trilinear, and PNG decoding to linear light.
#include "texture/texture.h"

#include <gtest/gtest.h>
#include <png.h>

#include <cmath>
#include <cstring>
#include <random>

#include "hwy/targets.h"
#include "texture/footprint.h"

namespace sv::texture {
namespace {

// Random texels; with `opaque`, alpha 1 everywhere (Texture::opaque).
Level randomLevel(int w, int h, unsigned seed, bool opaque = false) {
  std::mt19937 rng(seed);
  Level l;
  l.width = w;
  l.height = h;
  l.texels.resize(size_t(w) * size_t(h));
  for (Texel& t : l.texels)
    t = {uint16_t(rng() & 0xFFFF), uint16_t(rng() & 0xFFFF), uint16_t(rng() & 0xFFFF),
         uint16_t(opaque ? 0xFFFF : rng() & 0xFFFF)};
  return l;
}

TEST(Wrap, RepeatClampAndMirror) {
  const int expectRepeat[] = {2, 0, 1, 2, 0, 1, 2, 0, 1, 2, 0};
  const int expectClamp[] = {0, 0, 0, 0, 0, 1, 2, 2, 2, 2, 2};
  const int expectMirror[] = {2, 2, 1, 0, 0, 1, 2, 2, 1, 0, 0};
  for (int i = -4; i <= 6; ++i) {
    EXPECT_EQ(wrapIndex(i, 3, Wrap::repeat), expectRepeat[i + 4]) << i;
    EXPECT_EQ(wrapIndex(i, 3, Wrap::clamp), expectClamp[i + 4]) << i;
    EXPECT_EQ(wrapIndex(i, 3, Wrap::mirror), expectMirror[i + 4]) << i;
  }
}

// Every texel of every level against the 3×3 triangle filter of the level above, written out
// independently: weights (2 − |dx|)(2 − |dy|) / 16, centred on texel (2x, 2y), rounded to nearest.
// The pyramid is filtered in 16 bits (nextLevel) and each level stored packed: the Texture's levels
// are exactly the packed 16-bit levels, each row followed by its wrapped neighbour (texture.h).
TEST(Pyramid, LevelsAreTheTriangleFilterOfTheLevelAboveDecimatedByTwo) {
  for (Wrap wrap : {Wrap::repeat, Wrap::clamp, Wrap::mirror}) {
    std::vector<Level> chain{randomLevel(13, 7, 3)};
    while (chain.back().width > 1 || chain.back().height > 1)
      chain.push_back(nextLevel(chain.back(), wrap, wrap));
    ASSERT_EQ(chain.size(), 5u);  // 13×7, 7×4, 4×2, 2×1, 1×1
    const int sizes[5][2] = {{13, 7}, {7, 4}, {4, 2}, {2, 1}, {1, 1}};
    for (size_t k = 1; k < chain.size(); ++k) {
      const Level &above = chain[k - 1], &level = chain[k];
      ASSERT_EQ(level.width, sizes[k][0]);
      ASSERT_EQ(level.height, sizes[k][1]);
      for (int y = 0; y < level.height; ++y)
        for (int x = 0; x < level.width; ++x) {
          double sum[4] = {};
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const Texel& t = above.at(wrapIndex(2 * x + dx, above.width, wrap),
                                        wrapIndex(2 * y + dy, above.height, wrap));
              const double w = (2 - std::abs(dx)) * (2 - std::abs(dy)) / 16.0;
              sum[0] += w * t.r;
              sum[1] += w * t.g;
              sum[2] += w * t.b;
              sum[3] += w * t.a;
            }
          const Texel& got = level.at(x, y);
          const uint16_t c[4] = {got.r, got.g, got.b, got.a};
          for (int ch = 0; ch < 4; ++ch)
            ASSERT_EQ(c[ch], uint16_t(std::floor(sum[ch] + 0.5)))
                << "level " << k << " texel " << x << "," << y << " channel " << ch;
        }
    }
    const Texture tex(chain[0], wrap, wrap);
    ASSERT_EQ(tex.levelCount(), 5);
    for (int k = 0; k < tex.levelCount(); ++k) {
      const LevelView view = tex.level(k);
      const Level& level = chain[size_t(k)];
      ASSERT_EQ(view.width, level.width);
      ASSERT_EQ(view.height, level.height);
      ASSERT_EQ(view.texels.size(), size_t(level.width + 1) * size_t(level.height));
      for (int y = 0; y < level.height; ++y)
        for (int x = 0; x <= level.width; ++x)
          ASSERT_EQ(view.packed(x, y), packTexel(level.at(wrapIndex(x, level.width, wrap), y)))
              << "level " << k << " texel " << x << "," << y;
    }
  }
}

TEST(Pyramid, ConstantImageStaysConstantAndOneTexelIsItsOwnPyramid) {
  Level l;
  l.width = 10;
  l.height = 6;
  l.texels.assign(60, Texel{1000, 2000, 3000, 65535});
  const Texture tex(l, Wrap::repeat, Wrap::clamp);
  for (int k = 0; k < tex.levelCount(); ++k)
    for (PackedTexel t : tex.level(k).texels)
      EXPECT_EQ(t, packTexel(Texel{1000, 2000, 3000, 65535}));
  Level one;
  one.width = one.height = 1;
  one.texels = {Texel{7, 8, 9, 10}};
  EXPECT_EQ(Texture(one, Wrap::repeat, Wrap::repeat).levelCount(), 1);
}

// The stored format (texture.h): colour within half a code of the square-root curve, alpha within
// half a code, black, white and opaque exact, and premultiplied colour never above alpha.
TEST(PackedTexels, RoundTripWithinHalfACodeAndPremultipliedColourStaysBelowAlpha) {
  std::mt19937 rng(5);
  for (int i = 0; i < 200000; ++i) {
    const uint16_t a = i < 1000 ? 65535 : uint16_t(rng() & 0xFFFF);
    const uint16_t c = uint16_t(uint32_t(rng() & 0xFFFF) * a / 65535);  // premultiplied: c ≤ a
    const Color4 back = unpackTexel(packTexel({c, c, c, a}));
    const double alpha = a / 65535.0;
    EXPECT_LE(std::fabs(back.a - alpha), 0.5 / 255 + 1e-7) << a;
    EXPECT_LE(back.r, back.a) << c << " " << a;
    // Half a code in the square-root domain, unless that code reads above alpha: then the
    // largest code that does not.
    const int code = int(std::lround(std::sqrt(back.r) * 255));
    if (std::fabs(std::sqrt(back.r) - std::sqrt(c / 65535.0)) > 0.5 / 255 + 1e-6) {
      EXPECT_GT(float((code + 1) * (code + 1)) * (1.0f / 65025.0f), back.a) << c << " " << a;
    }
    ASSERT_EQ(back.r, back.g);
    ASSERT_EQ(back.r, back.b);
  }
  EXPECT_EQ(packTexel({0, 0, 0, 0}), 0u);
  EXPECT_EQ(packTexel({65535, 65535, 65535, 65535}), 0xFFFFFFFFu);
  const Color4 white = unpackTexel(0xFFFFFFFFu);
  EXPECT_EQ(white.r, 1.0f);
  EXPECT_EQ(white.a, 1.0f);
  EXPECT_EQ(unpackTexel(packTexel({0, 0, 0, 65535})).r, 0.0f);
}

float channel(const Color4& c) { return c.r; }
float value(const Texture& t, int x, int y) { return t.texel(0, x, y).r; }

// SPEC §7, seed 001: Θ ≥ γ: R = γR3 + (Θ − γ)R4 + (1 − Θ)R1; Θ < γ: R = ΘR3 + (γ − Θ)R2 + (1 −
// γ)R1, with R1…R4 at (0,0), (1,0), (1,1), (0,1).
TEST(Samplers, ThreePointFollowsTheSeedAtCornersDiagonalAndCentre) {
  const Texture tex(randomLevel(4, 4, 9), Wrap::repeat, Wrap::repeat);
  const float r1 = value(tex, 1, 1), r2 = value(tex, 2, 1), r3 = value(tex, 2, 2),
              r4 = value(tex, 1, 2);
  const float eps = 1e-6f;
  // Corners: the texels themselves.
  EXPECT_NEAR(channel(tex.threePoint(0, 1, 1)), r1, eps);
  EXPECT_NEAR(channel(tex.threePoint(0, 2, 1)), r2, eps);
  EXPECT_NEAR(channel(tex.threePoint(0, 2, 2)), r3, eps);
  EXPECT_NEAR(channel(tex.threePoint(0, 1, 2)), r4, eps);
  // The diagonal γ = Θ: only R1 and R3 contribute.
  for (float s : {0.25f, 0.5f, 0.75f})
    EXPECT_NEAR(channel(tex.threePoint(0, 1 + s, 1 + s)), s * r3 + (1 - s) * r1, eps) << s;
  // The centre lies on the diagonal: the mean of R1 and R3 — where bilinear takes all four.
  EXPECT_NEAR(channel(tex.threePoint(0, 1.5f, 1.5f)), 0.5f * (r1 + r3), eps);
  EXPECT_NEAR(channel(tex.bilinear(0, 1.5f, 1.5f)), 0.25f * (r1 + r2 + r3 + r4), eps);
  // Either side of the diagonal, the seed's two formulas.
  EXPECT_NEAR(channel(tex.threePoint(0, 1.25f, 1.75f)), 0.25f * r3 + 0.5f * r4 + 0.25f * r1, eps);
  EXPECT_NEAR(channel(tex.threePoint(0, 1.75f, 1.25f)), 0.25f * r3 + 0.5f * r2 + 0.25f * r1, eps);
}

TEST(Samplers, NearestBilinearAndTrilinear) {
  const Texture tex(randomLevel(8, 8, 11), Wrap::repeat, Wrap::repeat);
  EXPECT_NEAR(channel(tex.nearest(0, 2.4f, 5.6f)), value(tex, 2, 6), 1e-6f);
  EXPECT_NEAR(channel(tex.nearest(0, -0.6f, 0.2f)), value(tex, 7, 0), 1e-6f);  // wrapped
  // Bilinear is exact at texel centres and linear along an edge.
  EXPECT_NEAR(channel(tex.bilinear(0, 3, 4)), value(tex, 3, 4), 1e-6f);
  EXPECT_NEAR(channel(tex.bilinear(0, 3.25f, 4)),
              0.75f * value(tex, 3, 4) + 0.25f * value(tex, 4, 4), 1e-6f);
  // Trilinear: an integer level of detail is that level's bilinear sample (level-0 coordinates
  // scaled by 2^-k); halfway between two levels is their mean.
  EXPECT_NEAR(channel(tex.trilinear(1, 4.0f, 6.0f)), channel(tex.bilinear(1, 2.0f, 3.0f)), 1e-6f);
  const float a = channel(tex.bilinear(1, 2.5f, 1.5f)), b = channel(tex.bilinear(2, 1.25f, 0.75f));
  EXPECT_NEAR(channel(tex.trilinear(1.5f, 5.0f, 3.0f)), 0.5f * (a + b), 1e-6f);
  EXPECT_NEAR(
      channel(tex.trilinearThreePoint(1.5f, 5.0f, 3.0f)),
      0.5f * (channel(tex.threePoint(1, 2.5f, 1.5f)) + channel(tex.threePoint(2, 1.25f, 0.75f))),
      1e-6f);
  // Beyond the last level the 1×1 level is all there is.
  EXPECT_NEAR(channel(tex.trilinear(10, 3, 3)), tex.level(3).at(0, 0).r, 1e-6f);
}

// Anisotropic filtering keeps detail across a long, thin footprint that the trilinear filter, sized
// by the major axis, blurs away: horizontal stripes 4 texels high, a footprint 16 texels long along
// u and 1 across. Trilinear at log2(16) averages the stripes to grey; the probes stay in the white.
TEST(Samplers, AnisotropicKeepsDetailAcrossAThinFootprint) {
  Level l;
  l.width = l.height = 64;
  l.texels.resize(64 * 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      l.texels[size_t(y) * 64 + size_t(x)] =
          (y / 4) % 2 ? Texel{65535, 65535, 65535, 65535} : Texel{0, 0, 0, 65535};
  const Texture tex(l, Wrap::repeat, Wrap::repeat);
  Footprint f;
  f.major = 16;
  f.minor = 1;
  f.axisX = 1;
  f.axisY = 0;
  f.lod = 4;
  const float x = 20, y = 5.5f;  // the middle of the white band at rows 4…7
  const float aniso = tex.anisotropic(f, x, y).r, tri = tex.trilinear(4, x, y).r;
  EXPECT_GT(aniso, 0.9f);
  EXPECT_NEAR(tri, 0.5f, 0.1f);
  // An isotropic footprint is one trilinear probe at its own level of detail.
  f.minor = 16;
  const Color4 one = tex.anisotropic(f, x, y), ref = tex.trilinear(4, x, y);
  EXPECT_FLOAT_EQ(one.r, ref.r);
}

// The SIMD block sampler returns Texture::sample's values bit for bit, for every filter and wrap
// mode, on every compiled SIMD target — including levels of detail below 0, past the last level,
// NaN, coordinates far outside the texture, huge or NaN, and clusters of points anywhere (which
// take the paired reads where they can).
TEST(Samplers, SimdBlockEqualsScalarOnEveryTarget) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> u(0, 1);
  const Filter filters[] = {Filter::nearest, Filter::threePoint, Filter::bilinear,
                            Filter::trilinearThreePoint, Filter::trilinear};
  int targets = 0;
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    // Odd sizes, and powers of two (whose wrapping is a mask); translucent and opaque texels.
    for (const auto& [w, h] : {std::pair{37, 20}, std::pair{64, 16}})
      for (Wrap wrap : {Wrap::repeat, Wrap::clamp, Wrap::mirror})
        for (bool opaque : {false, true}) {
          const Texture tex(randomLevel(w, h, 5, opaque), wrap, Wrap(2 - int(wrap)));
          ASSERT_EQ(tex.opaque(), opaque);
          for (Filter f : filters)
            for (int round = 0; round < 40; ++round) {
              float lod[16], x[16], y[16], out[4][16];
              for (int i = 0; i < 16; ++i) {
                lod[i] = u(rng) * 8 - 1;
                x[i] = u(rng) * 200 - 80;
                y[i] = u(rng) * 120 - 50;
              }
              if (round % 3 == 1) {
                // A cluster of points, as a block of pixels gives: inside the image the sampler
                // reads each row's two texels as one pair, and at the right edge the row's border
                // copy.
                const float cx = u(rng) * float(w + 6) - 3, cy = u(rng) * float(h + 6) - 3;
                const float level = u(rng) * 3;
                for (int i = 0; i < 16; ++i) {
                  lod[i] = level;
                  x[i] = cx + u(rng) * 3;
                  y[i] = cy + u(rng) * 3;
                }
              }
              if (round == 0) {
                lod[0] = std::nanf("");
                x[1] = std::nanf("");
                y[2] = 3e9f;
                x[3] = -1e20f;
                lod[4] = 100;
                lod[5] = 2;  // an exact level: no blend
              }
              const int count = 1 + round % 16;
              sampleBlock(tex, f, lod, x, y, count, out);
              for (int i = 0; i < count; ++i) {
                const Color4 c = tex.sample(f, lod[i], x[i], y[i]);
                const float expect[4] = {c.r, c.g, c.b, c.a};
                for (int ch = 0; ch < 4; ++ch)
                  ASSERT_EQ(std::memcmp(&out[ch][i], &expect[ch], sizeof(float)), 0)
                      << hwy::TargetName(target) << " filter " << int(f) << " wrap " << int(wrap)
                      << " opaque " << opaque << " point " << i << " channel " << ch << ": "
                      << out[ch][i] << " vs " << expect[ch];
              }
            }
        }
    ++targets;
  }
  hwy::SetSupportedTargetsForTest(0);
  EXPECT_GE(targets, 1);
}

// A PNG in memory through libpng's simplified writer.
std::vector<uint8_t> encodePng(int w, int h, uint32_t format, const void* pixels) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = uint32_t(w);
  png.height = uint32_t(h);
  png.format = format;
  png_alloc_size_t size = 0;
  EXPECT_TRUE(png_image_write_to_memory(&png, nullptr, &size, 0, pixels, 0, nullptr));
  std::vector<uint8_t> out(size);
  EXPECT_TRUE(png_image_write_to_memory(&png, out.data(), &size, 0, pixels, 0, nullptr));
  out.resize(size);
  return out;
}

// The packed SIMD anisotropic filter returns Texture::anisotropic's values bit for bit on every
// compiled target: footprints from round to 16:1 and beyond (probes straddling sampleBlock calls),
// degenerate ones, and partial blocks.
TEST(Samplers, AnisotropicBlockEqualsScalarOnEveryTarget) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> u(0, 1);
  const Texture translucent(randomLevel(64, 48, 2), Wrap::repeat, Wrap::clamp);
  const Texture opaque(randomLevel(64, 48, 2, true), Wrap::repeat, Wrap::clamp);
  int targets = 0;
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    for (int round = 0; round < 60; ++round) {
      const Texture& tex = round / 16 % 2 ? opaque : translucent;  // every count on both
      Footprint fp[16];
      float x[16], y[16], out[4][16];
      for (int i = 0; i < 16; ++i) {
        const double angle = u(rng) * 6.283;
        fp[i].minor = std::exp2(u(rng) * 6 - 2);
        fp[i].major = fp[i].minor * std::exp2(u(rng) * 5);  // 1:1 to 32:1
        fp[i].axisX = std::cos(angle);
        fp[i].axisY = std::sin(angle);
        x[i] = u(rng) * 150 - 40;
        y[i] = u(rng) * 100 - 30;
      }
      if (round % 16 == 3) {            // four pixels checked, on both textures
        fp[0].major = fp[0].minor = 0;  // a degenerate footprint
        fp[1].major = 1e30;
        x[2] = std::nanf("");
      }
      const int count = 1 + round % 16;
      anisotropicBlock(tex, fp, x, y, count, out);
      for (int i = 0; i < count; ++i) {
        const Color4 c = tex.anisotropic(fp[i], x[i], y[i]);
        const float expect[4] = {c.r, c.g, c.b, c.a};
        for (int ch = 0; ch < 4; ++ch)
          ASSERT_EQ(std::memcmp(&out[ch][i], &expect[ch], sizeof(float)), 0)
              << hwy::TargetName(target) << " round " << round << " pixel " << i << " channel "
              << ch << ": " << out[ch][i] << " vs " << expect[ch];
      }
    }
    ++targets;
  }
  hwy::SetSupportedTargetsForTest(0);
  EXPECT_GE(targets, 1);
}

// An opaque texture reads alpha exactly 1 with every filter, without reading alpha: the seed's
// three-point blend of ones, γ·1 + (Θ − γ)·1 + (1 − Θ)·1, comes out an ulp off 1 at some
// weights, and shading divides the colour by alpha. One translucent texel anywhere in the pyramid
// makes the texture translucent.
TEST(Samplers, OpaqueTextureReadsAlphaExactlyOne) {
  const Texture tex(randomLevel(16, 16, 4, true), Wrap::repeat, Wrap::repeat);
  ASSERT_TRUE(tex.opaque());
  std::mt19937 rng(6);
  std::uniform_real_distribution<float> u(0, 1);
  const Filter filters[] = {Filter::nearest, Filter::threePoint, Filter::bilinear,
                            Filter::trilinearThreePoint, Filter::trilinear};
  int offOne = 0;
  for (int i = 0; i < 2000; ++i) {
    // Small coordinates: their fractions, the blend weights, keep all their bits.
    const float lod = u(rng) * 4, x = u(rng) * 3, y = u(rng) * 3;
    for (Filter f : filters) ASSERT_EQ(tex.sample(f, lod, x, y).a, 1.0f) << int(f);
    Footprint fp;
    fp.minor = 0.5 + u(rng);
    fp.major = fp.minor * (1 + 8 * u(rng));
    fp.axisX = 0.6;
    fp.axisY = 0.8;
    ASSERT_EQ(tex.anisotropic(fp, x, y).a, 1.0f);
    const float a = u(rng), b = u(rng), g = std::min(a, b), t = std::max(a, b);
    offOne += (1.0f * g + 1.0f * (t - g)) + 1.0f * (1.0f - t) != 1.0f;
  }
  EXPECT_GT(offOne, 0) << "no weights show the rounding the rule guards against";
  Level one = randomLevel(16, 16, 4, true);
  one.texels[37].a = 65000;
  EXPECT_FALSE(Texture(std::move(one), Wrap::repeat, Wrap::repeat).opaque());
}

TEST(TextureImage, PngDecodesToLinearLightWithPremultipliedAlpha) {
  // 8-bit grey, sRGB: 0, 188 (linear 0.5029 by the sRGB curve, 32 956), 255.
  const uint8_t grey[3] = {0, 188, 255};
  auto png = encodePng(3, 1, PNG_FORMAT_GRAY, grey);
  auto l = decodeTextureImage(png.data(), png.size(), "grey.png");
  ASSERT_TRUE(l.ok()) << l.error().str();
  EXPECT_EQ(l->texels[0], (Texel{0, 0, 0, 65535}));
  EXPECT_NEAR(l->texels[1].g, 32956, 1);
  EXPECT_EQ(l->texels[2], (Texel{65535, 65535, 65535, 65535}));
  // 8-bit RGBA: white at half alpha comes out premultiplied.
  const uint8_t rgba[8] = {255, 255, 255, 128, 255, 0, 0, 255};
  png = encodePng(2, 1, PNG_FORMAT_RGBA, rgba);
  l = decodeTextureImage(png.data(), png.size(), "rgba.png");
  ASSERT_TRUE(l.ok()) << l.error().str();
  EXPECT_EQ(l->texels[0].a, 32896);  // 128/255
  EXPECT_EQ(l->texels[0].r, 32896);
  EXPECT_EQ(l->texels[1], (Texel{65535, 0, 0, 65535}));
  // 16-bit linear RGB round-trips exactly.
  const uint16_t rgb16[6] = {1, 30000, 65535, 12345, 0, 40000};
  png = encodePng(2, 1, PNG_FORMAT_LINEAR_RGB, rgb16);
  l = decodeTextureImage(png.data(), png.size(), "rgb16.png");
  ASSERT_TRUE(l.ok()) << l.error().str();
  EXPECT_EQ(l->texels[0], (Texel{1, 30000, 65535, 65535}));
  EXPECT_EQ(l->texels[1], (Texel{12345, 0, 40000, 65535}));
}

TEST(TextureImage, ErrorsNameTheFileAndTheProblem) {
  const uint8_t junk[16] = {0x89, 'P', 'N', 'G', 1, 2, 3};
  auto l = decodeTextureImage(junk, sizeof(junk), "junk.png");
  ASSERT_FALSE(l.ok());
  EXPECT_EQ(l.error().file, "junk.png");
  EXPECT_FALSE(l.error().message.empty());
  // Wider than the limit.
  std::vector<uint8_t> wide(size_t(kMaxTextureSide) + 1, 7);
  auto png = encodePng(kMaxTextureSide + 1, 1, PNG_FORMAT_GRAY, wide.data());
  l = decodeTextureImage(png.data(), png.size(), "wide.png");
  ASSERT_FALSE(l.ok());
  EXPECT_NE(l.error().message.find("out of range"), std::string::npos) << l.error().message;
  // A header stating more image than the bytes can hold is refused before allocating it.
  std::vector<uint8_t> big(size_t(4096) * 4096, 0);
  png = encodePng(4096, 4096, PNG_FORMAT_GRAY, big.data());
  png.resize(200);  // a few hundred bytes cannot hold 16 M pixels
  l = decodeTextureImage(png.data(), png.size(), "short.png");
  ASSERT_FALSE(l.ok());
  EXPECT_NE(l.error().message.find("cannot hold"), std::string::npos) << l.error().message;
  l = readTextureImage("/no/such/texture.png");
  ASSERT_FALSE(l.ok());
  EXPECT_EQ(l.error().file, "/no/such/texture.png");
}

}  // namespace
}  // namespace sv::texture
