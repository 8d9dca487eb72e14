// The block-at-a-time splat addition (lights/splat_blocks.h) against one pixel at a time, on every
// SIMD target the build generates: the same rounding, the same saturation, nothing outside the
// splat's part of the tile touched.
#include "lights/splat_blocks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "hwy/targets.h"
#include "raster/framebuffer.h"

namespace sv::lights {
namespace {

using raster::FrameBuffer;

// One pixel at a time, the arithmetic the pass states: ⌊rgb · kx · ky + ½⌋, saturating.
void addSplatPerPixel(uint16_t* color, int samples, const SplatInTile& s) {
  for (int y = s.y0; y <= s.y1; ++y)
    for (int x = s.x0; x <= s.x1; ++x) {
      const float w = s.kx[x - s.kernelX] * s.ky[y - s.kernelY];
      for (int ch = 0; ch < 3; ++ch) {
        const int add = int(s.rgb[ch] * w + 0.5f);
        for (int k = 0; k < samples; ++k) {
          uint16_t& c = color[FrameBuffer::colorOffset(x, y, ch, samples, k)];
          c = uint16_t(std::min(65535, int(c) + add));
        }
      }
    }
}

TEST(SplatBlocks, BlocksEqualOnePixelAtATimeOnEveryTarget) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> weight(0.0f, 1.0f);
  std::uniform_int_distribution<int> start(-3, 63), span(1, 9), value(0, 65535);
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    for (const int samples : {1, 4}) {
      const size_t size = size_t(raster::kTilePixels) * 3 * size_t(samples);
      std::vector<uint16_t> base(size);
      for (uint16_t& c : base) c = uint16_t(value(rng));
      std::vector<uint16_t> blocks = base, pixels = base;
      for (int trial = 0; trial < 300; ++trial) {
        float kx[9], ky[9];
        for (float& w : kx) w = weight(rng);
        for (float& w : ky) w = weight(rng);
        SplatInTile s;
        s.kx = kx;
        s.ky = ky;
        s.kernelX = start(rng);
        s.kernelY = start(rng);
        s.x0 = std::max(0, s.kernelX);
        s.x1 = std::min(63, s.kernelX + span(rng) - 1);
        s.y0 = std::max(0, s.kernelY);
        s.y1 = std::min(63, s.kernelY + span(rng) - 1);
        // From faint to far past saturation.
        const float scale = trial % 3 == 0 ? 3.0f : trial % 3 == 1 ? 900.0f : 1e6f;
        for (float& c : s.rgb) c = scale * weight(rng);
        if (s.x0 > s.x1 || s.y0 > s.y1) continue;
        addSplat(blocks.data(), samples, s);
        addSplatPerPixel(pixels.data(), samples, s);
      }
      ASSERT_EQ(blocks, pixels) << hwy::TargetName(target) << ", " << samples << " samples";
      EXPECT_NE(blocks, base);
      EXPECT_GT(std::count(blocks.begin(), blocks.end(), uint16_t(65535)), 0);
    }
  }
  hwy::SetSupportedTargetsForTest(0);
}

}  // namespace
}  // namespace sv::lights
