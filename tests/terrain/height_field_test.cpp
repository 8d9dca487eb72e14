#include "terrain/height_field.h"

#include <gtest/gtest.h>

#include <cmath>

#include "formats/heights.h"

namespace sv::terrain {
namespace {

// Tables to cast over, made as the formats make them.
using formats::generateFractal;
using formats::quantize;

TEST(HeightField, BothFiltersReproduceTheTableAtGridPoints) {
  const HeightField f = generateFractal(33, 10, 500, 7).value();
  for (Interpolation interp : {Interpolation::bilinear, Interpolation::bicubic})
    for (int j = 0; j < f.height; ++j)
      for (int i = 0; i < f.width; ++i)
        ASSERT_NEAR(interpolate(f, interp, i, j), f.at(i, j), 1e-9 * 500)
            << interpolationName(interp) << " at " << i << ", " << j;
}

TEST(HeightField, DerivativesMatchDifferences) {
  const HeightField f = generateFractal(17, 10, 500, 3).value();
  for (Interpolation interp : {Interpolation::bilinear, Interpolation::bicubic})
    for (double x : {2.3, 7.71, 11.5})
      for (double y : {1.2, 5.55, 13.9}) {
        double dx, dy;
        interpolate(f, interp, x, y, &dx, &dy);
        const double e = 1e-6;
        EXPECT_NEAR(dx, (interpolate(f, interp, x + e, y) - interpolate(f, interp, x - e, y)) / (2 * e),
                    1e-3);
        EXPECT_NEAR(dy, (interpolate(f, interp, x, y + e) - interpolate(f, interp, x, y - e)) / (2 * e),
                    1e-3);
      }
}

TEST(HeightField, FractalIsSeededAndSpansItsRelief) {
  const HeightField a = generateFractal(65, 5, 300, 11).value();
  const HeightField b = generateFractal(65, 5, 300, 11).value();
  const HeightField c = generateFractal(65, 5, 300, 12).value();
  EXPECT_EQ(a.q, b.q);
  EXPECT_NE(a.q, c.q);
  EXPECT_EQ(*std::min_element(a.q.begin(), a.q.end()), 0);
  EXPECT_EQ(*std::max_element(a.q.begin(), a.q.end()), 65535);
  EXPECT_NEAR(a.at(0, 0) + a.scale * 0, a.offset + a.scale * a.code(0, 0), 1e-12);
  EXPECT_DOUBLE_EQ(a.eastU() - a.originU, 64 * 5.0);
}

TEST(HeightField, QuantizeRefusesEmptyAndAbsurdTables) {
  EXPECT_FALSE(quantize({NAN, NAN, NAN, NAN}, 2, 2, "x").ok());
  EXPECT_FALSE(quantize({1, 2}, 2, 1, "x").ok());
  EXPECT_FALSE(generateFractal(scene::kMaxHeightSide + 1, 1, 1, 0).ok());
  const HeightField f = quantize({1, NAN, 3, 5}, 2, 2, "x").value();
  EXPECT_NEAR(f.at(1, 0), 1, 1e-9);  // no data takes the lowest height
  EXPECT_NEAR(f.at(1, 1), 5, 1e-9);
}

}  // namespace
}  // namespace sv::terrain
