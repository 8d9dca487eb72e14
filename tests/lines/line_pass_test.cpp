// The line pass: a strip covers width × length pixels at any angle and sub-pixel place (its
// anti-aliasing), is hidden by what is in front and hides what is behind, shows over the surface it
// lies on, clips at the eye, fogs like a surface, and draws the same frame for any thread count.
#include "lines/line_pass.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "support/test_scenes.h"
#include "synthvis/image.h"
#include "synthvis/render.h"
#include "synthvis/scene.h"

namespace sv {
namespace {

constexpr int kW = 200, kH = 160;

// A camera at the origin looking down −z, 90° vertical field: at depth 10 one unit is kH/20
// pixels. Black background, no light needed (lines are unlit).
scene::Scene emptyScene() {
  scene::Scene s = tests::emptyScene(1000);
  s.cameras[0].yfovDegrees = 90;
  return s;
}

// The raster point (px, py) at eye depth `depth`, in the world of emptyScene().
Vec3 at(float px, float py, float depth) {
  const float unit = float(kH) / 2;  // pixels per unit at depth 1
  return {(px - float(kW) / 2) / unit * depth, (float(kH) / 2 - py) / unit * depth, -depth};
}

Image render(const scene::Scene& s, int samples, int threads = 2, FrameStats* stats = nullptr) {
  RenderOptions o;
  o.width = kW;
  o.height = kH;
  o.samples = samples;
  o.threads = threads;
  o.gamma = 1;  // linear 8-bit: a pixel's value is its covered fraction times 255
  Renderer r(o);
  Image img;
  EXPECT_TRUE(r.render(s, img, stats).ok());
  return img;
}

// The red channel summed over the frame, in pixels of full red.
double coverage(const Image& img) {
  double sum = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) sum += img.pixel(x, y)[0];
  return sum / 255;
}

// Anti-aliasing: a red strip's pixels sum to its area (width × (length + width), square caps) at
// any angle and sub-pixel offset, within the sample pattern's error; one sample per pixel
// point-samples it (each pixel all or nothing, the sum the area only on average).
TEST(LinePass, CoversItsAreaAtAnyAngle) {
  for (float width : {1.0f, 2.5f}) {
    for (int a = 0; a < 12; ++a) {
      const float angle = float(a) * 0.29f, len = 90;
      const float cx = 100.3f + float(a) * 0.07f, cy = 80.6f - float(a) * 0.05f;
      const float dx = std::cos(angle) * len / 2, dy = std::sin(angle) * len / 2;
      scene::Scene s = emptyScene();
      s.lineSettings.width = width;
      s.lines.push_back({at(cx - dx, cy - dy, 10), at(cx + dx, cy + dy, 10), {1, 0, 0}});
      const double expected = width * (len + width);
      const Image img = render(s, 16);
      EXPECT_NEAR(coverage(img), expected, 0.04 * expected) << "width " << width << ", angle "
                                                            << angle;
      const Image point = render(s, 1);
      for (size_t i = 0; i < point.rgb.size(); i += 3) ASSERT_TRUE(point.rgb[i] % 255 == 0);
      EXPECT_NEAR(coverage(point), expected, 0.25 * expected);
    }
  }
}

// A wall half across the line: the part behind it is hidden, the part in front of a farther wall
// drawn over it; a line lying on a wall (the same depth) shows.
TEST(LinePass, IsDepthTestedAgainstSurfaces) {
  scene::Scene s = emptyScene();
  s.light.ambient = 1;
  s.light.enabled = false;
  scene::Material grey;
  grey.baseColor = {0, 0.5f, 0, 1};
  grey.doubleSided = true;
  s.materials = {grey};
  scene::Mesh wall;  // the left half of the screen at depth 5
  wall.positions = {at(0, 0, 5), at(100, 0, 5), at(100, kH, 5), at(0, kH, 5)};
  wall.indices = {0, 1, 2, 0, 2, 3};
  wall.material = 0;
  s.meshes = {wall};
  s.instances = {{0, Mat4{}}};
  // At depth 10 across the screen (hidden on the left); at depth 5, on the wall (seen).
  // (Rows at pixel centres: y + ½.)
  s.lines.push_back({at(20, 40.5f, 10), at(180, 40.5f, 10), {1, 0, 0}});
  s.lines.push_back({at(20, 120.5f, 5), at(90, 120.5f, 5), {1, 0, 0}});
  for (int samples : {1, 8}) {
    const Image img = render(s, samples);
    EXPECT_EQ(img.pixel(50, 40)[0], 0) << samples;   // behind the wall
    EXPECT_GT(img.pixel(50, 40)[1], 0) << samples;   // the wall
    EXPECT_EQ(img.pixel(150, 40)[0], 255) << samples;  // in the open
    EXPECT_EQ(img.pixel(50, 120)[0], 255) << samples;  // on the wall
  }
  // A line in front of the wall hides it.
  s.lines = {{at(20, 80.5f, 3), at(90, 80.5f, 3), {1, 0, 0}}};
  const Image img = render(s, 8);
  EXPECT_EQ(img.pixel(50, 80)[0], 255);
  EXPECT_EQ(img.pixel(50, 80)[1], 0);
}

// A segment through the eye's plane is drawn up to the near plane; one wholly behind is not; fog
// blends a line into the fog colour by its true distance, as it does a surface.
TEST(LinePass, ClipsAtTheEyeAndFogs) {
  scene::Scene s = emptyScene();
  s.lines.push_back({{0, -1, -20}, {0, -1, 20}, {1, 1, 1}});  // from far ahead to behind the eye
  s.lines.push_back({{-1, 0, 5}, {1, 0, 5}, {1, 1, 1}});      // behind the eye
  FrameStats stats;
  Image img = render(s, 4, 2, &stats);
  EXPECT_EQ(stats.lines, 2u);
  EXPECT_EQ(stats.linesDrawn, 1u);
  EXPECT_GT(coverage(img), 10);
  // Fog: a white line whose ends are at distance 10, in blue fog of β = 0.1.
  s = emptyScene();
  s.fog = {true, {0, 0, 1}, 0.1f};
  const Vec3 left = at(60, 80.5f, 10), right = at(140, 80.5f, 10);
  s.lines.push_back({left * (10 / length(left)), right * (10 / length(right)), {1, 1, 1}});
  img = render(s, 1);
  // The chord's middle is 10·cos(atan ½) = 8.944 away: 255·2^−0.8944 = 137.2 of red left, and
  // blue (white plus the fog's blue) stays full; near an end, 10 away: 127.5.
  EXPECT_NEAR(img.pixel(99, 80)[0], 137, 1);
  EXPECT_EQ(img.pixel(99, 80)[2], 255);
  EXPECT_NEAR(img.pixel(60, 80)[0], 128, 1);
}

// The same frame for 1, 2 and 5 threads: many lines across many tiles.
TEST(LinePass, FramesAreBitIdenticalForAnyThreadCount) {
  scene::Scene s = emptyScene();
  uint32_t seed = 11;
  auto next = [&] {
    seed = seed * 1664525u + 1013904223u;
    return float(seed >> 8) / float(1 << 24);
  };
  for (int i = 0; i < 5000; ++i) {
    const Vec3 a{next() * 40 - 20, next() * 30 - 15, -next() * 40 - 1};
    const Vec3 b = a + Vec3{next() * 6 - 3, next() * 6 - 3, next() * 6 - 3};
    s.lines.push_back({a, b, {next(), next(), next()}});
  }
  for (int samples : {1, 8}) {
    const Image ref = render(s, samples, 1);
    for (int threads : {2, 5})
      EXPECT_TRUE(render(s, samples, threads).rgb == ref.rgb)
          << threads << " threads, " << samples << " samples";
  }
}

// Bad lines and settings are refused with a clear message.
TEST(LinePass, MalformedLinesAreRefused) {
  scene::Scene s = emptyScene();
  s.lines.push_back({{0, 0, -1}, {NAN, 0, -1}, {1, 1, 1}});
  EXPECT_EQ(scene::validate(s, "t").error().str(), "t: lines[0]: not finite, or a negative colour");
  s.lines = {{{0, 0, -1}, {1, 0, -1}, {1, 1, 1}}};
  s.lineSettings.width = 100;
  EXPECT_FALSE(scene::validate(s, "t").ok());
}

}  // namespace
}  // namespace sv
