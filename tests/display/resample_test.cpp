// Method (b), the resampling of a flat image through a display's directions: exact where the
// display looks at the flat pixel centres or at a sub-pixel shift of a ramp, Keys's cubic exact on
// quadratics and sharper than bilinear on a step, directions off the image black and counted, and
// the covering flat view holding the whole 3-projector cylinder rig.
#include "display/resample.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

namespace sv::display {
namespace {

constexpr double kToDegrees = 180 / std::numbers::pi;

// A flat view whose pixel centres sit at dyadic tangents: 48 × 32 pixels of tangent step 1/32
// over [−0.75, 0.75] × [−0.5, 0.5], looking straight ahead (rotationOf is then exactly the
// identity). Directions (tx, ty, −1) at such tangents are exact in float, so a display looking at
// them lands on the flat centres to within the window's own rounding (1e-15 px).
FlatView dyadicView() {
  FlatView v;
  v.window = {std::atan(-0.75) * kToDegrees, std::atan(0.75) * kToDegrees,
              std::atan(-0.5) * kToDegrees, std::atan(0.5) * kToDegrees};
  v.width = 48;
  v.height = 32;
  return v;
}

// The direction through the flat view's continuous pixel (fx, fy), unnormalized: tangents on the
// plane at distance 1, turned by the orientation.
Vec3 directionAt(const FlatView& v, double fx, double fy) {
  const WindowTangents t = tangentsOf(v.window);
  const double tx = t.left + fx / v.width * (t.right - t.left);
  const double ty = t.up - fy / v.height * (t.up - t.down);
  return rotationOf(v.orientation).apply(tx, ty, -1);
}

DirectionMap emptyMap(int w, int h) {
  DirectionMap m;
  m.width = w;
  m.height = h;
  m.directions.assign(size_t(w) * size_t(h), Vec3{});
  m.valid.assign(size_t(w) * size_t(h), 0);
  return m;
}
void set(DirectionMap& m, int x, int y, Vec3 d) {
  m.directions[size_t(y) * size_t(m.width) + size_t(x)] = d;
  m.valid[size_t(y) * size_t(m.width) + size_t(x)] = 1;
}

// A display looking at the flat view's pixel (i + dx + 0.5, j + dy + 0.5) from its pixel (i − x0,
// j − y0), for i in [x0, x1), j in [y0, y1).
DirectionMap shiftedMap(const FlatView& v, int x0, int x1, int y0, int y1, double dx, double dy) {
  DirectionMap m = emptyMap(x1 - x0, y1 - y0);
  for (int j = y0; j < y1; ++j)
    for (int i = x0; i < x1; ++i)
      set(m, i - x0, j - y0, directionAt(v, i + dx + 0.5, j + dy + 0.5));
  return m;
}

std::vector<uint16_t> image(const FlatView& v, const auto& value) {
  std::vector<uint16_t> rgb(size_t(v.width) * size_t(v.height) * 3);
  for (int j = 0; j < v.height; ++j)
    for (int i = 0; i < v.width; ++i)
      for (int c = 0; c < 3; ++c)
        rgb[(size_t(j) * size_t(v.width) + size_t(i)) * 3 + size_t(c)] = uint16_t(value(i, j, c));
  return rgb;
}

TEST(Resample, DisplayLookingAtTheFlatPixelCentresReproducesTheImageExactly) {
  const FlatView v = dyadicView();
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> any(0, 65535);
  const std::vector<uint16_t> flat = image(v, [&](int, int, int) { return any(rng); });
  const DirectionMap display = shiftedMap(v, 0, v.width, 0, v.height, 0, 0);
  for (ResampleFilter f : {ResampleFilter::bilinear, ResampleFilter::bicubic}) {
    const ResampledImage out = resampleFlatImage(v, flat.data(), display, f);
    EXPECT_EQ(out.outside, 0);
    EXPECT_EQ(out.invalid, 0);
    EXPECT_EQ(out.rgb, flat) << int(f);
  }
}

TEST(Resample, UnitFloatDirectionsOfATurnedViewReproduceTheImageWithinRounding) {
  // The display stage's directions are unit float vectors (7e-8 rad of rounding): through a view
  // turned in all three angles, a random 16-bit image comes back within a code or so.
  FlatView v = dyadicView();
  v.orientation = {37, -12, 8};
  std::mt19937 rng(6);
  std::uniform_int_distribution<int> any(0, 65535);
  const std::vector<uint16_t> flat = image(v, [&](int, int, int) { return any(rng); });
  DirectionMap display = shiftedMap(v, 0, v.width, 0, v.height, 0, 0);
  for (Vec3& d : display.directions) d = normalize(d);
  for (ResampleFilter f : {ResampleFilter::bilinear, ResampleFilter::bicubic}) {
    const ResampledImage out = resampleFlatImage(v, flat.data(), display, f);
    int worst = 0;
    for (size_t i = 0; i < flat.size(); ++i)
      worst = std::max(worst, std::abs(out.rgb[i] - flat[i]));
    std::printf("%s, turned view, unit float directions: largest difference %d codes\n",
                f == ResampleFilter::bilinear ? "bilinear" : "bicubic", worst);
    EXPECT_LE(worst, 2);
  }
}

TEST(Resample, SubPixelShiftOfALinearRampIsExactForBothFilters) {
  // value = 1000 + 400·x + 96·y (and other slopes per channel) at flat centre (x, y) = (i, j):
  // at a shift of (0.25, 0.375) every value is a whole code, so exact means equal.
  const FlatView v = dyadicView();
  auto ramp = [](double x, double y, int c) {
    return 1000 + (400 - 100 * c) * x + (96 + 64 * c) * y;
  };
  const std::vector<uint16_t> flat = image(v, [&](int i, int j, int c) { return ramp(i, j, c); });
  // The display's pixels look inside the flat image, away from its clamped edge (two pixels for
  // the cubic's footprint).
  const DirectionMap display = shiftedMap(v, 2, v.width - 3, 2, v.height - 3, 0.25, 0.375);
  for (ResampleFilter f : {ResampleFilter::bilinear, ResampleFilter::bicubic}) {
    const ResampledImage out = resampleFlatImage(v, flat.data(), display, f);
    int mismatches = 0;
    for (int y = 0; y < display.height; ++y)
      for (int x = 0; x < display.width; ++x)
        for (int c = 0; c < 3; ++c) {
          const double want = ramp(x + 2 + 0.25, y + 2 + 0.375, c);
          mismatches += out.rgb[(size_t(y) * size_t(display.width) + size_t(x)) * 3 + size_t(c)] !=
                        uint16_t(want);
        }
    EXPECT_EQ(mismatches, 0) << int(f);
  }
}

TEST(Resample, BicubicReproducesAQuadraticWhichBilinearDoesNot) {
  // Keys's a = −1/2 is exact for polynomials of degree 2: 4·(x − 20)² + 4·(y − 14)² + 1000 at
  // half-pixel shifts is a whole code everywhere; bilinear's chords lie above the parabolas by
  // 4/4 + 4/4 codes there.
  const FlatView v = dyadicView();
  auto quad = [](double x, double y) {
    return 4 * (x - 20) * (x - 20) + 4 * (y - 14) * (y - 14) + 1000;
  };
  const std::vector<uint16_t> flat = image(v, [&](int i, int j, int) { return quad(i, j); });
  const DirectionMap display = shiftedMap(v, 2, v.width - 3, 2, v.height - 3, 0.5, 0.5);
  int cubicWorst = 0, linearWorst = 0;
  for (ResampleFilter f : {ResampleFilter::bilinear, ResampleFilter::bicubic}) {
    const ResampledImage out = resampleFlatImage(v, flat.data(), display, f);
    for (int y = 0; y < display.height; ++y)
      for (int x = 0; x < display.width; ++x) {
        const int want = int(quad(x + 2.5, y + 2.5));
        const int d = std::abs(out.rgb[(size_t(y) * size_t(display.width) + size_t(x)) * 3] - want);
        (f == ResampleFilter::bicubic ? cubicWorst : linearWorst) =
            std::max(f == ResampleFilter::bicubic ? cubicWorst : linearWorst, d);
      }
  }
  EXPECT_EQ(cubicWorst, 0);
  EXPECT_EQ(linearWorst, 2);
}

// The 10 %–90 % rise of a profile sampled at positions `x`, in the positions' unit (linear
// interpolation between samples).
double riseWidth(const std::vector<double>& x, const std::vector<double>& value, double lo,
                 double hi) {
  auto crossing = [&](double level) {
    for (size_t i = 1; i < value.size(); ++i)
      if (value[i - 1] < level && value[i] >= level)
        return x[i - 1] + (level - value[i - 1]) / (value[i] - value[i - 1]) * (x[i] - x[i - 1]);
    return std::nan("");
  };
  return crossing(lo + 0.9 * (hi - lo)) - crossing(lo + 0.1 * (hi - lo));
}

TEST(Resample, BicubicIsSharperThanBilinearOnAStep) {
  // A vertical step between columns 23 and 24 (16384 | 49152, away from the clamp so that the
  // cubic's overshoot is kept), sampled by the display at a sixteenth of a flat pixel across it.
  const FlatView v = dyadicView();
  const std::vector<uint16_t> flat =
      image(v, [](int i, int, int) { return i < 24 ? 16384 : 49152; });
  constexpr int kSamples = 16 * 8;
  DirectionMap display = emptyMap(kSamples, 1);
  std::vector<double> x(kSamples);
  for (int k = 0; k < kSamples; ++k) {
    x[size_t(k)] = 20 + k / 16.0;
    set(display, k, 0, directionAt(v, x[size_t(k)], 16.5));
  }
  // Two measures: the 10–90 % rise width, and the steepest slope (in steps per flat pixel).
  double width[2] = {0, 0}, slope[2] = {0, 0};
  for (ResampleFilter f : {ResampleFilter::bilinear, ResampleFilter::bicubic}) {
    const ResampledImage out = resampleFlatImage(v, flat.data(), display, f);
    std::vector<double> value(kSamples);
    for (int k = 0; k < kSamples; ++k) value[size_t(k)] = out.rgb[size_t(k) * 3];
    width[int(f)] = riseWidth(x, value, 16384, 49152);
    for (int k = 1; k < kSamples; ++k)
      slope[int(f)] =
          std::max(slope[int(f)], (value[size_t(k)] - value[size_t(k) - 1]) * 16 / 32768);
  }
  std::printf(
      "step edge: 10-90%% rise bilinear %.3f flat pixels, bicubic %.3f (%.0f%%); steepest "
      "slope bilinear %.3f, bicubic %.3f steps per pixel\n",
      width[0], width[1], 100 * width[1] / width[0], slope[0], slope[1]);
  EXPECT_NEAR(width[0], 0.8, 0.01);  // the tent's rise: 0.1 to 0.9 of a pixel
  EXPECT_NEAR(slope[0], 1, 0.01);    // and its slope, one step per pixel
  // Catmull–Rom's slope midway between the step's samples is 5/4 of a step per pixel.
  EXPECT_LT(width[1], 0.92 * width[0]);
  EXPECT_GT(slope[1], 1.2);
}

TEST(Resample, DirectionsOffTheFlatImageAreBlackAndCounted) {
  const FlatView v = dyadicView();
  const std::vector<uint16_t> flat = image(v, [](int, int, int) { return 30000; });
  DirectionMap display = emptyMap(6, 1);
  set(display, 0, 0, directionAt(v, 10, 10));         // inside
  set(display, 1, 0, directionAt(v, -0.01, 5));       // just left of the image
  set(display, 2, 0, directionAt(v, 5, 32.01));       // just below
  set(display, 3, 0, Vec3{0.1f, 0, 1});               // behind the camera
  set(display, 4, 0, directionAt(v, 47.999, 0.001));  // by the top-right corner: inside
  // Pixel 5 stays invalid.
  for (ResampleFilter f : {ResampleFilter::bilinear, ResampleFilter::bicubic}) {
    const ResampledImage out = resampleFlatImage(v, flat.data(), display, f);
    EXPECT_EQ(out.outside, 3);
    EXPECT_EQ(out.invalid, 1);
    for (int k = 0; k < 6; ++k) {
      const bool lit = k == 0 || k == 4;
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(out.rgb[size_t(k) * 3 + size_t(c)], lit ? 30000 : 0) << k;
    }
  }
}

TEST(Resample, CoveringFlatViewHoldsEveryDirectionOfTheCylinderRig) {
  const CylinderRig rig = threeProjectorCylinder(3, 10, 320, 200);
  for (int i = 0; i < 3; ++i) {
    const DirectionMap display = directionMap(rig.geometry(i));
    const Orientation o = meanOrientation(display);
    constexpr int kMargin = 2;
    const Result<FlatView> view = coveringFlatView(display, o, kMargin);
    ASSERT_TRUE(view.ok()) << view.error().str();
    const FlatView& v = view.value();
    // Every valid direction lands inside the margin; some land on each of its four lines (the
    // window is tight up to the rounding to whole pixels).
    double minX = 1e9, maxX = -1e9, minY = 1e9, maxY = -1e9;
    for (int y = 0; y < display.height; ++y)
      for (int x = 0; x < display.width; ++x) {
        ASSERT_TRUE(display.isValid(x, y));
        const std::optional<FlatPoint> p = flatPointOf(v, display.direction(x, y));
        ASSERT_TRUE(p);
        minX = std::min(minX, p->x), maxX = std::max(maxX, p->x);
        minY = std::min(minY, p->y), maxY = std::max(maxY, p->y);
      }
    EXPECT_GE(minX, kMargin - 1e-6);
    EXPECT_LE(maxX, v.width - kMargin + 1e-6);
    EXPECT_GE(minY, kMargin - 1e-6);
    EXPECT_LE(maxY, v.height - kMargin + 1e-6);
    EXPECT_LT(minX, kMargin + 1);
    EXPECT_GT(maxX, v.width - kMargin - 1);
    EXPECT_LT(minY, kMargin + 1);
    EXPECT_GT(maxY, v.height - kMargin - 1);
    // The flat tangent step is at most the display's finest angle.
    const WindowTangents t = tangentsOf(v.window);
    const double finest = finestAngularPixel(display);
    EXPECT_LE((t.right - t.left) / v.width, finest * (1 + 1e-9));
    EXPECT_LE((t.up - t.down) / v.height, finest * (1 + 1e-9));
    // Resampled through it, no pixel is outside.
    const std::vector<uint16_t> flat(size_t(v.width) * size_t(v.height) * 3, 1000);
    EXPECT_EQ(resampleFlatImage(v, flat.data(), display, ResampleFilter::bicubic).outside, 0);
    std::printf(
        "projector %d (320 x 200): flat view %d x %d, window [%.2f, %.2f] x [%.2f, %.2f] "
        "deg, yaw %.2f pitch %.2f, finest display pixel %.3g rad\n",
        i, v.width, v.height, v.window.leftDegrees, v.window.rightDegrees, v.window.downDegrees,
        v.window.upDegrees, o.yawDegrees, o.pitchDegrees, finest);
  }
}

TEST(Resample, CoveringFlatViewRefusesDirectionsBehindIt) {
  DirectionMap display = emptyMap(2, 1);
  set(display, 0, 0, Vec3{0, 0, -1});
  set(display, 1, 0, Vec3{0, 0, 1});
  const Result<FlatView> v = coveringFlatView(display, Orientation{});
  ASSERT_FALSE(v.ok());
  EXPECT_NE(v.error().message.find("display pixel (1, 0) looks behind"), std::string::npos)
      << v.error().str();
  EXPECT_FALSE(coveringFlatView(emptyMap(2, 2), Orientation{}).ok());
}

}  // namespace
}  // namespace sv::display
