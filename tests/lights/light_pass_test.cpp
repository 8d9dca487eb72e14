// The light pass (SPEC §13): energy kept below the minimum size, visibility against walls and
// grazing ground, whole frames across thread counts, and the scene format's errors.
#include "lights/light_pass.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/thread_pool.h"
#include "raster/framebuffer.h"
#include "synthvis/formats.h"
#include "synthvis/image.h"
#include "synthvis/render.h"
#include "synthvis/scene.h"

namespace sv {
namespace {

using raster::FrameBuffer;
using raster::kTileSize;

// A bare frame: depth at the far plane, colour black; the pass drawn into every tile.
struct BareFrame {
  explicit BareFrame(int w, int h, int samples = 1) : pool(2) {
    fb.resize(w, h, samples);
    clear();
  }
  void clear() {
    for (int t = 0; t < fb.tileCount(); ++t)
      std::fill_n(fb.tileDepth(t), raster::kTilePixels * fb.samples(), 1.0f);
    clearColor();
  }
  void clearColor() {
    for (int t = 0; t < fb.tileCount(); ++t)
      std::fill_n(fb.tileColor(t), raster::kTilePixels * 3 * fb.samples(), uint16_t(0));
  }
  float& depth(int x, int y, int k) {
    return fb.tileDepth((y / kTileSize) * fb.tilesX() +
                        x / kTileSize)[FrameBuffer::depthOffset(x, y, fb.samples(), k)];
  }
  void draw(lights::LightPass& pass) {
    pass.prepare(raster::PassFrame{fb.width(), fb.height(), fb.samples(), nullptr, &pool});
    for (int t = 0; t < fb.tileCount(); ++t)
      pass.seeTile({t % fb.tilesX(), t / fb.tilesX(), fb.tileDepth(t), fb.tileColor(t), 0});
    for (int t = 0; t < fb.tileCount(); ++t)
      pass.drawTile({t % fb.tilesX(), t / fb.tilesX(), fb.tileDepth(t), fb.tileColor(t), 0});
  }
  // The sum of channel `ch` over the frame, in 16-bit linear units.
  double total(int ch) {
    double sum = 0;
    for (int y = 0; y < fb.height(); ++y)
      for (int x = 0; x < fb.width(); ++x) {
        const int t = (y / kTileSize) * fb.tilesX() + x / kTileSize;
        for (int k = 0; k < fb.samples(); ++k)
          sum += fb.tileColor(t)[FrameBuffer::colorOffset(x, y, ch, fb.samples(), k)];
      }
    return sum;
  }
  core::ThreadPool pool;
  FrameBuffer fb;
};

// A camera at the origin looking down −z with a 90° vertical field (1 unit of x at depth 1 is
// height/2 pixels), depth range [0.1, 1000].
lights::LightInput cameraInput(int w, int h) {
  lights::LightInput in;
  in.view = Mat4{};
  in.projection = Mat4::perspective(std::numbers::pi_v<float> / 2, float(w) / float(h), 0.1f, 1000);
  return in;
}

TEST(LightPass, EnergyIsKeptBelowTheMinimumSizeWhereverTheLightFalls) {
  BareFrame f(128, 128);
  std::vector<scene::LightAppearance> looks(1);
  looks[0].intensity = 1;
  looks[0].color = {1, 1, 1};
  std::vector<scene::LightPoint> points(1);
  lights::LightInput in = cameraInput(128, 128);
  in.appearances = looks;
  in.points = points;
  in.settings.exposure = 0.02f * 100;  // at d = 10: Φ = 0.02 pixel of white: far below 1.5 px
  in.settings.minSize = 1.5f;
  const double expected = 0.02 * 65535;
  double lo = 1e30, hi = 0;
  // Across a pixel and into the next tile (x = 64 is a tile edge), in 1/8-pixel steps.
  for (int i = 0; i <= 24; ++i)
    for (int j = 0; j <= 8; j += 4) {
      const float px = 61.3f + float(i) / 8, py = 40.0f + float(j) / 8;
      // The point at depth 10 that projects to raster (px, py).
      points[0].position = {(px / 64 - 1) * 10, (1 - py / 64) * 10, -10};
      points[0].position = points[0].position * (1 / length(points[0].position)) * 10;
      lights::LightPass pass;
      pass.setLights(in);
      f.clear();
      f.draw(pass);
      ASSERT_EQ(pass.splats().size(), 1u);
      const double sum = f.total(0);
      lo = std::min(lo, sum);
      hi = std::max(hi, sum);
    }
  // Each touched pixel rounds its share to a whole 16-bit step: at most ½ a step each, over the
  // few pixels a 1.5-px kernel reaches (≤ 9): the total stays within 4.5 steps of Φ.
  EXPECT_GE(lo, expected - 4.5);
  EXPECT_LE(hi, expected + 4.5);
  EXPECT_LT((hi - lo) / expected, 0.01) << "lo " << lo << " hi " << hi << " of " << expected;
}

// A light's visibility reads its centre pixel and the eight around it (docs/lights.md); centred on
// a tile's outermost pixels, some of those lie in the next tile, and the pass reads them from the
// border that tile's seeTile kept. Depth: a wall at eye depth 5 in front of the lights (at 20), with
// holes (the far plane) scattered over the pixels around the tile edges — whole pixels, and with
// 4 samples some pixels whose odd samples alone are holes. By the rule, a light is seen whole when
// one of the nine pixels' first sample differs from the centre's (the spread), else in the share
// of its centre's samples that are holes.
TEST(LightPass, ALightOnATileEdgeIsSeenThroughTheDepthAcrossIt) {
  constexpr int size = 192;  // 3 × 3 tiles; the edges at 64 and 128
  for (const int samples : {1, 4}) {
    BareFrame f(size, size, samples);
    std::vector<scene::LightAppearance> looks(1);
    looks[0].intensity = 1;
    std::vector<scene::LightPoint> points(1);
    lights::LightInput in = cameraInput(size, size);
    in.appearances = looks;
    in.points = points;
    in.settings.exposure = 400 * 400;  // a few pixels wide at depth 20
    const Vec4 wall = in.projection * Vec4{0, 0, -5, 1};
    const float wallDepth = (wall.z / wall.w + 1) / 2;
    // Where a light is centred at pixel (x, y): the point at eye depth 20 projecting there.
    const auto at = [&](int x, int y) {
      return Vec3{(float(x) + 0.5f) / (size / 2.0f) - 1, 1 - (float(y) + 0.5f) / (size / 2.0f),
                  -1} *
             20;
    };
    const auto drawLight = [&](int x, int y) {
      points[0].position = at(x, y);
      lights::LightPass pass;
      pass.setLights(in);
      f.clearColor();
      f.draw(pass);
      return f.total(0);
    };
    // The lights, centred on pixels within two of a tile edge, and each one's total with nothing in
    // front of it.
    std::vector<std::pair<int, int>> centres;
    for (const int edge : {64, 128})
      for (int across = edge - 2; across <= edge + 1; ++across)
        for (int along = 56; along < 136; along += 3) {
          centres.push_back({across, along});
          centres.push_back({along, across});
        }
    std::vector<double> whole;
    for (const auto& [x, y] : centres) whole.push_back(drawLight(x, y));
    uint32_t seed = 11;
    const auto next = [&] { return (seed = seed * 1664525u + 1013904223u) >> 8 & 0xffff; };
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const uint32_t r = next() % 8;  // 0: a hole, 1: odd samples holes (4 samples), else wall
        for (int k = 0; k < samples; ++k)
          f.depth(x, y, k) = r == 0 || (r == 1 && k % 2 == 1) ? 1.0f : wallDepth;
      }
    int seen = 0, hidden = 0, part = 0;
    for (size_t i = 0; i < centres.size(); ++i) {
      const auto [x, y] = centres[i];
      bool spread = false;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) spread |= f.depth(x + dx, y + dy, 0) != f.depth(x, y, 0);
      int holes = 0;
      for (int k = 0; k < samples; ++k) holes += f.depth(x, y, k) == 1.0f;
      const double got = drawLight(x, y);
      SCOPED_TRACE(testing::Message() << samples << " samples, light at " << x << ", " << y);
      ASSERT_GT(whole[i], 0);
      if (spread || holes == samples) {
        EXPECT_EQ(got, whole[i]);
        ++seen;
      } else if (holes == 0) {
        EXPECT_EQ(got, 0);
        ++hidden;
      } else {
        EXPECT_GT(got, 0);
        EXPECT_LT(got, whole[i]);
        ++part;
      }
    }
    EXPECT_GT(seen, 20);
    EXPECT_GT(hidden, 20);
    if (samples > 1) {
      EXPECT_GT(part, 5);
    }
  }
}

TEST(LightPass, SizeAndEnergyFollowDistanceAndFog) {
  BareFrame f(256, 256);
  std::vector<scene::LightAppearance> looks(1);
  looks[0].intensity = 50;
  std::vector<scene::LightPoint> points(1);
  lights::LightInput in = cameraInput(256, 256);
  in.appearances = looks;
  in.points = points;
  in.settings.exposure = 4;
  in.settings.maxSize = 3;
  for (float d : {5.0f, 10.0f, 20.0f})
    for (float beta : {0.0f, 0.05f}) {
      points[0].position = {0, 0, -d};
      in.fogBeta = beta;
      in.settings.punchThrough = 0.5f;
      lights::LightPass pass;
      pass.setLights(in);
      f.clear();
      f.draw(pass);
      ASSERT_EQ(pass.splats().size(), 1u);
      const double phi = 4.0 * 50 * std::exp2(-beta * 0.5 * d) / (d * d);
      // The kernel's radius: half the natural diameter 2·(15/16)·√Φ − 1, clamped, plus ½ pixel.
      const double diameter = std::clamp(2 * (15.0 / 16) * std::sqrt(phi) - 1, 1.5, 3.0);
      EXPECT_NEAR(pass.splats()[0].radius, diameter / 2 + 0.5, 1e-4) << d << " " << beta;
      // Full white saturates a pixel at 65535: compare the energy where no pixel can.
      if (pass.splats()[0].rgb[1] < 65535) {
        EXPECT_NEAR(f.total(1), phi * 65535, 20 + phi * 65535 * 1e-4) << d << " " << beta;
      }
    }
}

TEST(LightPass, ALightBehindAWallIsHiddenAndOneOnGrazingGroundIsNot) {
  // Scene: a wall at z = −20 covering x < 0, a ground plane y = 0 seen at a grazing angle; lights
  // behind the wall, beside it, and just above the ground far away.
  scene::Scene s;
  s.background = {0, 0, 0};
  s.light.enabled = false;
  scene::Material dark;
  dark.baseColor = {0.0f, 0.0f, 0.0f, 1};
  dark.doubleSided = true;
  s.materials.push_back(dark);
  scene::Mesh wall;
  wall.positions = {{-50, -5, -20}, {0, -5, -20}, {0, 30, -20}, {-50, 30, -20}};
  wall.indices = {0, 1, 2, 0, 2, 3};
  wall.material = 0;
  scene::Mesh ground;
  ground.positions = {{-500, 0, 10}, {500, 0, 10}, {500, 0, -3000}, {-500, 0, -3000}};
  ground.indices = {0, 1, 2, 0, 2, 3};
  ground.material = 0;
  s.meshes = {wall, ground};
  s.instances = {{0, Mat4{}}, {1, Mat4{}}};
  scene::Camera cam;
  cam.position = {0, 2, 0};
  cam.target = {0, 1.6f, -100};
  cam.yfovDegrees = 40;
  cam.znear = 0.5f;
  cam.zfar = 5000;
  s.cameras = {cam};
  s.lightAppearances.resize(1);
  s.lightAppearances[0].intensity = 2000;
  s.lightSettings.exposure = 1000;
  const Vec3 behind{-10, 4, -40}, beside{10, 4, -40};
  std::vector<Vec3> ground_lights;
  for (int k = 0; k < 8; ++k) ground_lights.push_back({float(k) * 3 + 5, 0.3f, -800 - 60 * float(k)});
  s.lightPoints.push_back({behind, 0, 0, -1});
  s.lightPoints.push_back({beside, 0, 0, -1});
  for (Vec3 p : ground_lights) s.lightPoints.push_back({p, 0, 0, -1});
  for (int samples : {1, 16}) {
    RenderOptions o;
    o.width = 320;
    o.height = 200;
    o.samples = samples;
    o.threads = 2;
    Renderer r(o);
    Image img;
    ASSERT_TRUE(r.render(s, img).ok());
    const Mat4 vp = viewProjection(s, o).value();
    auto brightness = [&](Vec3 p) {
      const Vec4 c = vp * Vec4{p.x, p.y, p.z, 1};
      const int x = int((c.x / c.w + 1) * 0.5f * float(o.width));
      const int y = int((1 - c.y / c.w) * 0.5f * float(o.height));
      return int(img.pixel(x, y)[0]);
    };
    EXPECT_EQ(brightness(behind), 0) << samples;
    EXPECT_GT(brightness(beside), 100) << samples;
    for (Vec3 p : ground_lights) EXPECT_GT(brightness(p), 20) << samples << " at z " << p.z;
  }
}

scene::Scene manyLights() {
  scene::Scene s;
  s.background = {0.01f, 0.01f, 0.02f};
  scene::Mesh box;
  box.positions = {{-3, -1, -12}, {3, -1, -12}, {3, 3, -12}, {-3, 3, -12}};
  box.indices = {0, 1, 2, 0, 2, 3};
  s.meshes = {box};
  s.instances = {{0, Mat4{}}};
  scene::Camera cam;
  cam.position = {0, 1, 5};
  cam.target = {0, 0, -20};
  s.cameras = {cam};
  s.lightAppearances.resize(2);
  s.lightAppearances[1].directional = true;
  s.lightAppearances[1].direction = {0, 0, 1};
  s.lightAppearances[1].color = {1, 0.3f, 0.1f};
  s.lightAppearances[1].blink = {.period = 1, .phase = 0, .onFraction = 0.5f};
  s.lightSettings.exposure = 400;
  uint32_t seed = 7;
  auto next = [&] {
    seed = seed * 1664525u + 1013904223u;
    return float(seed >> 8) / float(1 << 24);
  };
  for (int i = 0; i < 20000; ++i)
    s.lightPoints.push_back({{next() * 40 - 20, next() * 10 - 3, -next() * 60},
                             uint32_t(i % 2), next(), -1});
  return s;
}

TEST(LightPass, FramesAreBitIdenticalForAnyThreadCount) {
  const scene::Scene s = manyLights();
  for (int samples : {1, 8}) {
    Image ref;
    for (int threads : {1, 2, 5}) {
      RenderOptions o;
      o.width = 300;
      o.height = 170;
      o.samples = samples;
      o.threads = threads;
      Renderer r(o);
      Image img;
      FrameStats stats;
      ASSERT_TRUE(r.render(s, img, &stats).ok());
      EXPECT_EQ(stats.lightPoints, 20000u);
      EXPECT_GT(stats.lightsDrawn, 5000u);
      if (threads == 1)
        ref = img;
      else
        EXPECT_TRUE(img.rgb == ref.rgb) << threads << " threads, " << samples << " samples";
    }
  }
}

// Issue 60 item 3: the laws worked out once (LightLaws, for every channel that shares the eye) give
// the splats each view works out itself, bit for bit — groups off and dimmed, blinking, lobes, fog —
// for every light and for a subset.
TEST(LightPass, LawsWorkedOutOnceGiveTheSplatsEachViewWorksOut) {
  scene::Scene s = manyLights();
  s.lightGroups = {{"dimmed", true, 0.4f}, {"off", false, 1}};
  for (size_t i = 0; i < s.lightPoints.size(); ++i) s.lightPoints[i].group = int32_t(i % 3) - 1;
  BareFrame f(300, 170);
  lights::LightInput in = cameraInput(300, 170);
  in.view = Mat4::lookAt({0, 1, 5}, {0.5f, 0, -20}, {0, 1, 0});
  in.appearances = s.lightAppearances;
  in.points = s.lightPoints;
  in.groups = s.lightGroups;
  in.settings = s.lightSettings;
  in.fogBeta = 0.01f;
  in.time = 0.3;
  std::vector<uint32_t> subset;
  for (uint32_t i = 0; i < s.lightPoints.size(); i += 3) subset.push_back(i);
  lights::LightLaws laws;
  laws.compute(in, f.pool);
  for (const bool some : {false, true}) {
    in.subset = some ? &subset : nullptr;
    std::vector<lights::Splat> splats[2];
    std::vector<uint16_t> color[2];
    for (const bool shared : {false, true}) {
      in.laws = shared ? &laws : nullptr;
      lights::LightPass pass;
      pass.setLights(in);
      f.clear();
      f.draw(pass);
      splats[shared] = pass.splats();
      color[shared].assign(f.fb.tileColor(0),
                           f.fb.tileColor(0) + raster::kTilePixels * 3 * f.fb.tileCount());
    }
    SCOPED_TRACE(some ? "a subset" : "every light");
    ASSERT_EQ(splats[0].size(), splats[1].size());
    EXPECT_GT(splats[0].size(), some ? 1000u : 3000u);
    for (size_t i = 0; i < splats[0].size(); ++i) {
      const lights::Splat &a = splats[0][i], &b = splats[1][i];
      ASSERT_EQ(a.light, b.light);
      EXPECT_EQ(a.x, b.x);
      EXPECT_EQ(a.y, b.y);
      EXPECT_EQ(a.radius, b.radius);
      for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(a.rgb[ch], b.rgb[ch]) << "light " << a.light;
    }
    EXPECT_TRUE(color[0] == color[1]);
  }
}

TEST(LightPass, GroupsSwitchAndDim) {
  scene::Scene s = manyLights();
  s.lightGroups = {{"all", true, 1}};
  for (auto& p : s.lightPoints) p.group = 0;
  RenderOptions o;
  o.width = 160;
  o.height = 90;
  Renderer r(o);
  Image on, dim, off;
  FrameStats stats;
  ASSERT_TRUE(r.render(s, on).ok());
  s.lightGroups[0].dim = 0.25f;
  ASSERT_TRUE(r.render(s, dim).ok());
  s.lightGroups[0].on = false;
  ASSERT_TRUE(r.render(s, off, &stats).ok());
  EXPECT_EQ(stats.lightsDrawn, 0u);
  auto sum = [](const Image& i) {
    double t = 0;
    for (uint8_t v : i.rgb) t += v;
    return t;
  };
  EXPECT_GT(sum(on), sum(dim));
  EXPECT_GT(sum(dim), sum(off));
}

TEST(LightPass, MalformedLightsAndCataloguesGetAClearError) {
  const std::string head = R"({"synthvis": 1, "lights": )";
  struct Case {
    const char* lights;
    const char* message;
  };
  const Case cases[] = {
      {R"({"strings": [{"start": [0,0,0], "end": [10,0,0]}]})", "one of 'count' and 'spacing'"},
      {R"({"strings": [{"start": [0,0,0], "end": [1e9,0,0], "spacing": 0.001}]})",
       "more than 4194304 lights"},
      {R"({"strings": [{"start": [0,0,0], "end": [1,0,0], "count": 3, "appearance": "x"}]})",
       "no appearance named \"x\""},
      {R"({"points": [{"position": [0,0]}]})", "expected an array of 3 numbers"},
      {R"({"appearances": [{"lobe": [20, 10]}]})", "need a 'direction'"},
      {R"({"appearances": [{"direction": [0,0,1], "lobe": [200, 10]}]})", "lobe width"},
      {R"({"arrays": [{"origin": [0,0,0], "u": [1,0,0], "v": [0,1,0], "counts": [65536, 65536]}]})",
       "is more than"},
      {R"({"stars": {"catalog": "/nonexistent/BSC"}})", "/nonexistent/BSC"},
      {R"({"groups": [{"name": "a"}, {"name": "a"}]})", "a second group named 'a'"},
  };
  for (const Case& c : cases) {
    const Result<scene::Scene> r = formats::parseJsonScene(head + c.lights + "}", "t.json");
    ASSERT_FALSE(r.ok()) << c.lights;
    EXPECT_NE(r.error().str().find(c.message), std::string::npos) << r.error().str();
    EXPECT_EQ(r.error().str().find('\n'), std::string::npos);
  }
  const struct {
    const char* text;
    const char* message;
  } catalogues[] = {
      {"# nothing\n", "no stars"},
      {" 10.0  5.0\n", "line 1: expected 'declination right-ascension magnitude'"},
      {" 10.0  5.0  1.0 \"A\"\n 95.0  5.0  1.0\n", "line 2: declination 95"},
      {" 10.0  25.0  1.0\n", "right ascension 25"},
      {" 10.0  5.0  nan\n", "expected 'declination"},
      {" 10.0  5.0  1.0  9.0 \"A\"\n", "colour index 9"},
  };
  for (const auto& c : catalogues) {
    const auto r = formats::parseStarCatalog(c.text, "BSC");
    ASSERT_FALSE(r.ok()) << c.text;
    EXPECT_NE(r.error().str().find(c.message), std::string::npos) << r.error().str();
  }
}

TEST(LightPass, StringsArraysAndSequencesExpandAsDocumented) {
  const Result<scene::Scene> r = formats::parseJsonScene(R"({"synthvis": 1, "lights": {
    "appearances": [{"name": "w"}, {"name": "f", "blink": {"period": 0.5, "on": 0.1}}],
    "groups": [{"name": "g", "dim": 0.5}],
    "strings": [{"appearance": "f", "group": "g", "start": [0,0,0], "end": [0,0,-90],
                 "spacing": 30, "sequence": true}],
    "arrays": [{"origin": [1,2,3], "u": [1,0,0], "v": [0,0,1], "counts": [3, 2]}],
    "points": [{"position": [5,5,5], "appearance": 1, "phase": 0.25}]}})",
                                                         "t.json");
  ASSERT_TRUE(r.ok()) << r.error().str();
  const scene::Scene& s = r.value();
  // Points first, then strings, then arrays.
  ASSERT_EQ(s.lightPoints.size(), 1u + 4u + 6u);
  EXPECT_FLOAT_EQ(s.lightPoints[0].phase, 0.25f);
  for (int k = 0; k < 4; ++k) {
    const scene::LightPoint& p = s.lightPoints[size_t(1 + k)];
    EXPECT_FLOAT_EQ(p.position.z, -30.0f * float(k));
    EXPECT_FLOAT_EQ(p.phase, -float(k) / 4);
    EXPECT_EQ(p.appearance, 1u);
    EXPECT_EQ(p.group, 0);
  }
  EXPECT_FLOAT_EQ(s.lightPoints[5 + 5].position.x, 3);  // array (2, 1)
  EXPECT_FLOAT_EQ(s.lightPoints[5 + 5].position.z, 4);
  EXPECT_FLOAT_EQ(s.lightGroups[0].dim, 0.5f);
}

#ifdef SV_STAR_CATALOG
TEST(LightPass, XplanetsCatalogueReads) {
  const auto r = formats::loadStarCatalog(SV_STAR_CATALOG);
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_GT(r.value().size(), 9000u);  // 9 110 stars in the BSC, less the novae xplanet drops
  // Sirius first: Dec −16.7161°, RA 6.7525 h, magnitude −1.46.
  const scene::Star& sirius = r.value()[0];
  EXPECT_FLOAT_EQ(sirius.magnitude, -1.46f);
  EXPECT_NEAR(sirius.direction.z, std::sin(-16.7161 * std::numbers::pi / 180), 1e-6);
}
#endif

}  // namespace
}  // namespace sv
