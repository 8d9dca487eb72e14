// Whole frames through the public API: the demo scene's golden image, thread-count invariance,
// option validation, and the benchmark generator's stated statistics.
#include "synthvis/render.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <set>

#include "formats/primitives.h"
#include "synthvis/formats.h"
#include "synthvis/generators.h"

namespace sv {
namespace {

Image renderScene(const scene::Scene& s, int w, int h, int threads, FrameStats* stats = nullptr) {
  RenderOptions o;
  o.width = w;
  o.height = h;
  o.threads = threads;
  Renderer r(o);
  Image img;
  const Status st = r.render(s, img, stats);
  EXPECT_TRUE(st.ok()) << st.error().str();
  return img;
}

// Golden images are small (STYLE.md habit 12) and looked at by a person when they change:
// SV_UPDATE_GOLDEN=1 rewrites them instead of comparing.
TEST(Render, DemoSceneMatchesItsGoldenImage) {
  const std::string golden = std::string(SV_SOURCE_DIR) + "/tests/golden/demo_128x96.png";
  const Image img = renderScene(formats::demoScene(), 128, 96, 2);
  if (std::getenv("SV_UPDATE_GOLDEN")) {
    ASSERT_TRUE(writePng(img, golden).ok());
    GTEST_SKIP() << "golden image rewritten: " << golden;
  }
  auto ref = readPng(golden);
  ASSERT_TRUE(ref.ok()) << ref.error().str();
  ASSERT_EQ(ref->width, img.width);
  ASSERT_EQ(ref->height, img.height);
  // Bit-exact on this machine class; allow a few one-step differences should a libm's sin/cos
  // round the camera matrix differently elsewhere.
  int differing = 0, worst = 0;
  for (size_t i = 0; i < img.rgb.size(); ++i) {
    const int d = std::abs(int(img.rgb[i]) - int(ref->rgb[i]));
    differing += d != 0;
    worst = std::max(worst, d);
  }
  EXPECT_LE(differing, int(img.rgb.size() / 1000)) << "channels that differ";
  EXPECT_LE(worst, 2);
}

TEST(Render, DemoSceneIsNotEmptyAndShowsSeveralColours) {
  FrameStats stats;
  const Image img = renderScene(formats::demoScene(), 160, 120, 2, &stats);
  EXPECT_GT(stats.drawn, 1000u);
  EXPECT_GT(stats.culledFacing, 0u);  // closed objects: their back faces
  std::set<uint32_t> colours;
  for (size_t i = 0; i < img.rgb.size(); i += 3)
    colours.insert(img.rgb[i] << 16 | img.rgb[i + 1] << 8 | img.rgb[i + 2]);
  EXPECT_GT(colours.size(), 200u);
}

TEST(Render, DeterminismOneTwoAndEightThreadsGiveIdenticalBytes) {
  const scene::Scene demo = formats::demoScene();
  const Image one = renderScene(demo, 333, 201, 1);
  EXPECT_EQ(one.rgb, renderScene(demo, 333, 201, 2).rgb);
  EXPECT_EQ(one.rgb, renderScene(demo, 333, 201, 8).rgb);
  generators::TrisParams p;
  p.count = 20000;
  p.area = 30;
  p.width = 400;
  p.height = 300;
  const scene::Scene tris = generators::generateTris(p);
  const Image t1 = renderScene(tris, 400, 300, 1);
  EXPECT_EQ(t1.rgb, renderScene(tris, 400, 300, 2).rgb);
  EXPECT_EQ(t1.rgb, renderScene(tris, 400, 300, 8).rgb);
}

TEST(Render, OptionsOutOfRangeAreRejectedWithTheReason) {
  RenderOptions o;
  o.width = 0;
  EXPECT_FALSE(validate(o).ok());
  o.width = 9000;
  EXPECT_NE(validate(o).error().str().find("out of range"), std::string::npos);
  o.width = 64;
  o.threads = -1;
  EXPECT_FALSE(validate(o).ok());
  o.threads = 1;
  EXPECT_TRUE(validate(o).ok());
  o.camera = 3;
  Renderer r(o);
  Image img;
  EXPECT_FALSE(r.render(formats::demoScene(), img).ok());
}

// The renderer checks vertices and indices as its vertex stage reads them (not in a pass of
// validate's): a bad one is still refused with the loaders' message, naming mesh and element,
// however many vertex chunks the mesh spans, for any thread count — also where the draw order
// reads the meshes' bounds first (priority masking).
TEST(Render, BadVertexDataIsRefusedWithTheOffenderNamed) {
  scene::Scene base = formats::demoScene();
  ASSERT_FALSE(base.meshes.empty());
  // A mesh large enough for several vertex chunks (2^14 vertices each) and index chunks (2^16).
  scene::Mesh big;
  big.name = "big";
  for (int i = 0; i < 40000; ++i) {
    big.positions.push_back({float(i % 200) * 0.01f, float(i / 200) * 0.01f, 0});
    if (i >= 2)
      big.indices.insert(big.indices.end(), {uint32_t(i - 2), uint32_t(i - 1), uint32_t(i)});
  }
  base.meshes.push_back(big);
  scene::Instance instance;
  instance.mesh = int(base.meshes.size() - 1);
  base.instances.push_back(instance);
  const size_t m = base.meshes.size() - 1;
  for (int threads : {1, 2, 8}) {
    RenderOptions o;
    o.width = 64;
    o.height = 48;
    o.threads = threads;
    if (threads == 8) o.hsr = RenderOptions::Hsr::priority;
    Renderer r(o);
    Image img;
    ASSERT_TRUE(r.render(base, img).ok());
    scene::Scene nan = base;
    nan.meshes[m].positions[35000].y = std::nanf("");
    const Status a = r.render(nan, img);
    ASSERT_FALSE(a.ok());
    EXPECT_NE(a.error().str().find("'big': positions[35000] is not finite"), std::string::npos)
        << a.error().str();
    scene::Scene far = base;
    far.meshes[m].positions[17].x = INFINITY;
    const Status b = r.render(far, img);
    ASSERT_FALSE(b.ok());
    EXPECT_NE(b.error().str().find("positions[17] is not finite"), std::string::npos)
        << b.error().str();
    scene::Scene range = base;
    range.meshes[m].indices[3001] = 40000;
    const Status c = r.render(range, img);
    ASSERT_FALSE(c.ok());
    EXPECT_NE(c.error().str().find("indices[3001] = 40000 is out of range (40000 vertices)"),
              std::string::npos)
        << c.error().str();
    range = base;  // in the mesh's second chunk of indices (2^16 each)
    range.meshes[m].indices[100000] = 40001;
    const Status d = r.render(range, img);
    ASSERT_FALSE(d.ok());
    EXPECT_NE(d.error().str().find("indices[100000] = 40001 is out of range"), std::string::npos)
        << d.error().str();
    ASSERT_TRUE(r.render(base, img).ok());  // and the renderer is fine afterwards
  }
}

TEST(TrisGenerator, SameSeedSameSceneAndStatisticsWithinFivePercent) {
  generators::TrisParams p;
  p.count = 20000;
  p.area = 100;
  generators::TrisStats a, b;
  const scene::Scene s1 = generators::generateTris(p, &a), s2 = generators::generateTris(p, &b);
  ASSERT_EQ(s1.meshes[0].positions.size(), s2.meshes[0].positions.size());
  EXPECT_EQ(s1.meshes[0].positions[12345], s2.meshes[0].positions[12345]);
  EXPECT_NEAR(a.meanArea, 100, 5);
  p.depth = 4;
  generators::TrisStats d;
  generators::generateTris(p, &d);
  EXPECT_NEAR(d.depthComplexity, 4, 0.2);
  p.seed = 2;
  EXPECT_NE(generators::generateTris(p).meshes[0].positions[0], s1.meshes[0].positions[0]);
}

TEST(TrisGenerator, RenderedAreaMatchesTheRequestedArea) {
  generators::TrisParams p;
  p.count = 2000;
  p.area = 50;
  p.width = 640;
  p.height = 480;
  RenderOptions o;
  o.width = 640;
  o.height = 480;
  o.threads = 2;
  o.debugView = RenderOptions::DebugView::overdraw;  // counts covered pixels
  Renderer r(o);
  Image img;
  FrameStats stats;
  ASSERT_TRUE(r.render(generators::generateTris(p), img, &stats).ok());
  EXPECT_NEAR(double(stats.fragments) / p.count, 50, 2.5);
}

// A white quad (unlit, double-sided) on black whose right edge runs down the middle of column 10
// (x = 10.5) of a w × h image: column 9 fully covered, column 10 half, column 11 not at all.
scene::Scene halfCoveredColumnScene(int w, int h) {
  scene::Scene s = generators::benchCameraScene("quad");
  const double tanHalf = std::tan(30.0 * std::numbers::pi / 180), aspect = double(w) / h;
  auto at = [&](double px, double py) {
    return Vec3{float((2 * px / w - 1) * 2 * tanHalf * aspect),
                float((1 - 2 * py / h) * 2 * tanHalf), -2.0f};
  };
  scene::Mesh m;
  m.positions = {at(-5, -5), at(10.5, -5), at(10.5, h + 5), at(-5, h + 5)};
  m.indices = {0, 1, 2, 0, 2, 3};
  m.material = 0;  // unlit white, double-sided
  s.meshes.push_back(m);
  return s;
}

// Supersampling: a quad whose edge crosses column 10 at x = 10.5 covers half of that column's
// samples at k = 2, 4, 8 (linear 0.5 → sRGB 188), all of column 9 and none of 11.
TEST(Render, SupersamplingAveragesSamplesInLinearLight) {
  const int w = 40, h = 8;
  const scene::Scene s = halfCoveredColumnScene(w, h);
  for (int k : {2, 4, 8}) {
    RenderOptions o;
    o.width = w;
    o.height = h;
    o.threads = 2;
    o.supersample = k;
    Renderer r(o);
    Image img;
    ASSERT_TRUE(r.render(s, img).ok());
    for (int y = 0; y < h; ++y) {
      EXPECT_EQ(img.pixel(9, y)[0], 255) << k;
      EXPECT_NEAR(img.pixel(10, y)[1], 188, 1) << k;
      EXPECT_EQ(img.pixel(11, y)[2], 0) << k;
    }
  }
  RenderOptions bad;
  bad.supersample = 3;
  EXPECT_FALSE(validate(bad).ok());
  bad.supersample = 8;
  bad.width = 2000;
  EXPECT_FALSE(validate(bad).ok());  // 16 000 px wide inside
}

// A quad edge at x = 10.5 (vertical, through the middle of column 10) with anti-aliasing: column
// 10 is half covered — half its samples white, half black — and resolves to the sRGB encoding of
// 0.5 linear (188), as supersampling does; with the tent filter, column 10 is the weighted mean
// ¼·1 + ½·½ + ¼·0 = ½ of its neighbours too, and columns 9 and 11 blend by a quarter (¾ and ¼).
TEST(Render, AntiAliasingAndTheTentFilterAverageInLinearLight) {
  const int w = 40, h = 8;
  const scene::Scene s = halfCoveredColumnScene(w, h);
  auto render = [&](int samples, RenderOptions::Filter filter, int threads) {
    RenderOptions o;
    o.width = w;
    o.height = h;
    o.threads = threads;
    o.samples = samples;
    o.filter = filter;
    Renderer r(o);
    Image img;
    EXPECT_TRUE(r.render(s, img).ok());
    return img;
  };
  for (int n : {4, 8, 16, 64}) {
    const Image img = render(n, RenderOptions::Filter::box, 2);
    EXPECT_EQ(img.rgb, render(n, RenderOptions::Filter::box, 1).rgb) << n;
    for (int y = 0; y < h; ++y) {
      EXPECT_EQ(img.pixel(9, y)[0], 255) << n;
      EXPECT_NEAR(img.pixel(10, y)[1], 188, 1) << n;  // n/2 samples on each side of x = 10.5
      EXPECT_EQ(img.pixel(11, y)[2], 0) << n;
    }
    const Image tent = render(n, RenderOptions::Filter::tent3, 2);
    EXPECT_EQ(tent.rgb, render(n, RenderOptions::Filter::tent3, 1).rgb) << n;
    for (int y = 0; y < h; ++y) {
      EXPECT_EQ(tent.pixel(5, y)[0], 255) << n;
      EXPECT_NEAR(tent.pixel(9, y)[0], 240, 1) << n;   // sRGB of 0.875 = ¼ + ½ + ⅛
      EXPECT_NEAR(tent.pixel(10, y)[0], 188, 1) << n;  // 0.5
      EXPECT_NEAR(tent.pixel(11, y)[0], 99, 1) << n;   // 0.125
      EXPECT_EQ(tent.pixel(13, y)[0], 0) << n;
    }
  }
  RenderOptions bad;
  bad.samples = 2;
  EXPECT_NE(validate(bad).error().str().find("not supported"), std::string::npos);
  bad.samples = 16;
  bad.supersample = 2;
  EXPECT_FALSE(validate(bad).ok());
  bad.supersample = 1;
  bad.debugView = RenderOptions::DebugView::overdraw;
  EXPECT_FALSE(validate(bad).ok());
}

// The masking diagnostics (issue 6): where subdivision stopped, and which windows were occupied.
// BENCH.md's grazing scene: the sky is black in the levels view (nothing drawn), the ground plane
// is filled in whole windows, pixels along edges are leaf-tested (grey). Two of BENCH.md's layers
// front to back: the occupancy view shows every tile full (red) once both are in.
TEST(DebugViews, LevelsAndOccupancyShowTheSubdivisionAndTheMasks) {
  RenderOptions o;
  o.width = 256;
  o.height = 128;
  o.threads = 2;
  o.hsr = RenderOptions::Hsr::priority;
  o.debugView = RenderOptions::DebugView::levels;
  Image levels, occupancy;
  ASSERT_TRUE(Renderer(o).render(generators::generateGrazing({}), levels).ok());
  std::set<std::array<uint8_t, 3>> colours;
  for (size_t i = 0; i < levels.rgb.size(); i += 3)
    colours.insert({levels.rgb[i], levels.rgb[i + 1], levels.rgb[i + 2]});
  EXPECT_EQ(colours.count({0, 0, 0}), 1u) << "the sky";
  EXPECT_EQ(colours.count({128, 128, 128}), 1u) << "leaf-tested pixels along edges";
  EXPECT_GE(colours.size(), 3u) << "and pixels filled in whole windows";
  generators::LayersParams p;
  p.layers = 2;
  p.order = generators::SubmitOrder::frontToBack;
  p.width = o.width;
  p.height = o.height;
  o.debugView = RenderOptions::DebugView::occupancy;
  ASSERT_TRUE(Renderer(o).render(generators::generateLayers(p), occupancy).ok());
  for (size_t i = 0; i < occupancy.rgb.size(); i += 3)
    ASSERT_EQ(occupancy.rgb[i], 230) << "pixel " << i / 3 << " not in a full 64-px tile";
  o.hsr = RenderOptions::Hsr::zbuffer;
  EXPECT_FALSE(validate(o).ok()) << "occupancy needs masking";
}

TEST(LayersGenerator, SameSeedSameSceneAndStatistics) {
  generators::LayersParams p;
  p.layers = 3;
  generators::TrisStats a, b;
  const scene::Scene s1 = generators::generateLayers(p, &a), s2 = generators::generateLayers(p, &b);
  ASSERT_EQ(s1.meshes[0].positions.size(), s2.meshes[0].positions.size());
  EXPECT_EQ(s1.meshes[0].positions, s2.meshes[0].positions);
  EXPECT_EQ(s1.meshes[0].colors, s2.meshes[0].colors);
  EXPECT_NEAR(a.meanArea, 200, 10);  // BENCH.md: mean area 200 px, within 5 %
  EXPECT_NEAR(a.depthComplexity, 3, 0.15);
  p.seed = 2;
  EXPECT_NE(generators::generateLayers(p).meshes[0].positions, s1.meshes[0].positions);
}

// BENCH.md's layers are textured with fog: the flags add the bench texture and fog and change
// nothing else; every layer's UVs are a linear map of the screen with 0.5–4 texels per pixel.
TEST(LayersGenerator, TexturedAndFoggedLayersKeepTheirGeometry) {
  generators::LayersParams p;
  p.layers = 4;
  p.width = 640;
  p.height = 360;
  const scene::Scene plain = generators::generateLayers(p);
  p.textured = p.fog = true;
  const scene::Scene shaded = generators::generateLayers(p);
  EXPECT_EQ(plain.meshes[0].positions, shaded.meshes[0].positions);
  EXPECT_EQ(plain.meshes[0].colors, shaded.meshes[0].colors);
  EXPECT_EQ(plain.meshes[0].uvs, shaded.meshes[0].uvs);
  EXPECT_TRUE(plain.textures.empty());
  EXPECT_FALSE(plain.fog.enabled);
  ASSERT_EQ(shaded.textures.size(), 1u);
  EXPECT_EQ(shaded.materials[0].texture, 0);
  EXPECT_TRUE(shaded.fog.enabled);
  EXPECT_GT(shaded.fog.beta, 0);
  EXPECT_TRUE(scene::validate(shaded, "layers").ok());
  // Texels per pixel from a triangle's UVs and its (parallel-to-screen) pixel positions.
  const scene::Mesh& m = shaded.meshes[0];
  ASSERT_EQ(m.uvs.size(), m.positions.size());
  const double tanHalf = std::tan(30.0 * std::numbers::pi / 180.0);
  for (size_t t = 0; t < m.positions.size(); t += 3 * 97) {
    const Vec3 a = m.positions[t], b = m.positions[t + 1];
    const double pixelsPerUnit = p.height / (2 * tanHalf * -a.z);
    const double pixels = std::hypot(b.x - a.x, b.y - a.y) * pixelsPerUnit;
    const double texels =
        std::hypot(m.uvs[t + 1].x - m.uvs[t].x, m.uvs[t + 1].y - m.uvs[t].y) * 1024;
    EXPECT_GE(texels / pixels, 0.5 - 1e-3) << t;
    EXPECT_LE(texels / pixels, 4 + 1e-3) << t;
  }
}

// Priority masking on BENCH.md's layers given front to back, textured with fog: one sample draws
// the Z-buffer's image byte for byte (deferred shading included); with 16 samples the images differ
// only where two triangles of one layer claim the same sample near a shared vertex (area masks,
// docs/quality.md) — the Z-buffer keeps the nearer by a rounding of equal depths, masking the
// first. A translucent quad in front blends the same way over either.
TEST(LayersGenerator, PriorityMaskingDrawsTheZBufferImageOfOrderedLayers) {
  generators::LayersParams p;
  p.layers = 5;
  p.order = generators::SubmitOrder::frontToBack;
  p.width = 256;
  p.height = 160;
  p.textured = p.fog = true;
  scene::Scene s = generators::generateLayers(p);
  // A translucent quad nearer than every layer (drawn after the opaque triangles).
  scene::Material glass;
  glass.name = "glass";
  glass.unlit = true;
  glass.doubleSided = true;
  glass.alphaMode = scene::AlphaMode::blend;
  glass.baseColor = {0.9f, 0.2f, 0.1f, 0.4f};
  s.materials.push_back(glass);
  scene::Mesh quad;
  quad.positions = {{-0.5f, -0.4f, -1.5f}, {0.6f, -0.4f, -1.5f}, {0.6f, 0.5f, -1.5f}};
  quad.indices = {0, 1, 2};
  quad.material = int(s.materials.size()) - 1;
  s.meshes.push_back(quad);
  s.instances.push_back({int(s.meshes.size()) - 1, Mat4{}});
  for (int samples : {1, 16}) {
    RenderOptions o;
    o.width = p.width;
    o.height = p.height;
    o.threads = 2;
    o.samples = samples;
    Image z, m;
    FrameStats zs, ms;
    ASSERT_TRUE(Renderer(o).render(s, z, &zs).ok());
    o.hsr = RenderOptions::Hsr::priority;
    ASSERT_TRUE(Renderer(o).render(s, m, &ms).ok());
    EXPECT_GT(ms.occludedTriangles, 0u);
    EXPECT_LT(ms.fragments, zs.fragments);
    size_t differing = 0;
    int worst = 0;
    for (size_t i = 0; i < z.rgb.size(); ++i) {
      const int d = std::abs(int(z.rgb[i]) - int(m.rgb[i]));
      differing += d != 0;
      worst = std::max(worst, d);
    }
    if (samples == 1) {
      EXPECT_EQ(differing, 0u);
    } else {
      EXPECT_LT(differing, z.rgb.size() / 2000) << "channels differing";  // measured: 3 of 122 880
      EXPECT_LE(worst, 8) << "a sample of 16";                            // measured: 1
    }
  }
}

// Object-space culling (SPEC §4, seed 004) through the renderer: each instance's box, projected,
// is tested against the tiles' occupied windows before its triangles are. Cubes hidden behind a
// wall are dropped whole; those beside it, one reaching behind the eye (no bound) and a
// translucent one (never culled) are drawn; the image is the Z-buffer's at 1 and 16 samples.
TEST(ObjectCulling, HiddenInstancesAreDroppedWholeWithTheZBufferImage) {
  scene::Scene s;
  scene::Camera cam;
  cam.position = {0, 0, 0};
  cam.target = {0, 0, -1};
  cam.znear = 0.1f;
  cam.zfar = 100;
  s.cameras.push_back(cam);
  scene::Material wall, cube, glass;
  wall.baseColor = {0.8f, 0.7f, 0.6f, 1};
  cube.baseColor = {0.2f, 0.5f, 0.9f, 1};
  glass.baseColor = {0.9f, 0.2f, 0.1f, 0.5f};
  glass.alphaMode = scene::AlphaMode::blend;
  s.materials = {wall, cube, glass};
  scene::Mesh wallMesh = formats::detail::makeBox({3, 2, 0.1f});
  wallMesh.material = 0;
  scene::Mesh cubeMesh = formats::detail::makeBox({0.3f, 0.3f, 0.3f});
  cubeMesh.material = 1;
  scene::Mesh glassMesh = cubeMesh;
  glassMesh.material = 2;
  s.meshes = {wallMesh, cubeMesh, glassMesh};
  s.instances.push_back({0, Mat4::translation({0, 0, -3})});
  for (int i = 0; i < 60; ++i)
    s.instances.push_back(
        {1, Mat4::translation(
                {float(i % 10) * 0.8f - 3.6f, float(i / 10) * 0.6f - 1.5f, -5.0f - float(i % 7)})});
  s.instances.push_back({1, Mat4::translation({0.3f, -0.2f, -0.1f})});  // cut by the near plane
  s.instances.push_back({2, Mat4::translation({0.2f, 0.1f, -6})});      // translucent, hidden
  for (int samples : {1, 16}) {
    RenderOptions o;
    o.width = 200;
    o.height = 120;
    o.threads = 2;
    o.samples = samples;
    Image z;
    ASSERT_TRUE(Renderer(o).render(s, z).ok());
    for (auto hsr : {RenderOptions::Hsr::priority, RenderOptions::Hsr::hybrid}) {
      o.hsr = hsr;
      Image m;
      FrameStats stats;
      ASSERT_TRUE(Renderer(o).render(s, m, &stats).ok());
      EXPECT_EQ(m.rgb, z.rgb) << samples << " samples, " << hsrName(hsr);
      EXPECT_GT(stats.occludedObjects, 20u) << hsrName(hsr);
    }
  }
}

// Instances wholly outside the view volume are dropped before the vertex stage
// (RenderOptions::cullInstances): a field of boxes all around the eye — in front, behind, beyond
// every side and the far plane, straddling the edges and the near plane — gives the same image,
// with the same counts, as transforming every instance, for every hidden-surface method and with
// anti-aliasing, on one channel and on three.
TEST(ObjectCulling, InstancesOutsideTheViewAreDroppedWithTheSameImage) {
  scene::Scene s;
  scene::Camera cam;
  cam.position = {0, 1, 0};
  cam.target = {0.3f, 0.8f, -1};
  cam.znear = 0.2f;
  cam.zfar = 40;
  s.cameras.push_back(cam);
  scene::Material grey;
  grey.baseColor = {0.6f, 0.6f, 0.6f, 1};
  s.materials = {grey};
  scene::Mesh box = formats::detail::makeBox({0.8f, 0.8f, 0.8f});
  box.material = 0;
  s.meshes = {box};
  for (int x = -12; x <= 12; ++x)
    for (int z = -30; z <= 12; z += 2)
      s.instances.push_back(
          {0, Mat4::translation({float(x) * 1.7f, float((x * 7 + z) % 5) * 0.9f - 1, float(z) * 1.3f})});
  s.instances.push_back({0, Mat4::translation({0, 1, -0.3f})});  // cut by the near plane
  for (int samples : {1, 16})
    for (auto hsr : {RenderOptions::Hsr::zbuffer, RenderOptions::Hsr::priority}) {
      RenderOptions o;
      o.width = 160;
      o.height = 120;
      o.threads = 2;
      o.samples = samples;
      o.hsr = hsr;
      Image culled, all, tree;
      FrameStats withCulling, without, withTree;
      ASSERT_TRUE(Renderer(o).render(s, culled, &withCulling).ok());
      // The same through the instance tree (the traversal's hierarchy).
      scene::Scene indexed = s;
      scene::buildInstanceTree(indexed);
      ASSERT_TRUE(Renderer(o).render(indexed, tree, &withTree).ok());
      o.cullInstances = false;
      ASSERT_TRUE(Renderer(o).render(s, all, &without).ok());
      EXPECT_EQ(culled.rgb, all.rgb) << samples << " samples, " << hsrName(hsr);
      EXPECT_EQ(tree.rgb, all.rgb) << samples << " samples, " << hsrName(hsr);
      EXPECT_GT(withCulling.culledInstances, s.instances.size() / 2);
      EXPECT_EQ(withTree.culledInstances, withCulling.culledInstances);
      EXPECT_EQ(without.culledInstances, 0u);
      EXPECT_EQ(withCulling.trianglesIn, without.trianglesIn);
      EXPECT_EQ(withCulling.drawn, without.drawn);
      EXPECT_EQ(withCulling.culled(), without.culled());
      EXPECT_EQ(withTree.culled(), without.culled());
    }
  // Three channels in an arc: each channel culls against its own frustum.
  s.channels = scene::arcChannels(3, 150, 120, 90);
  RenderOptions o;
  o.threads = 2;
  std::vector<Image> culled, all;
  ASSERT_TRUE(Renderer(o).renderChannels(s, culled).ok());
  scene::buildInstanceTree(s);
  std::vector<Image> tree;
  ASSERT_TRUE(Renderer(o).renderChannels(s, tree).ok());
  o.cullInstances = false;
  ASSERT_TRUE(Renderer(o).renderChannels(s, all).ok());
  ASSERT_EQ(culled.size(), 3u);
  for (size_t c = 0; c < 3; ++c) {
    EXPECT_EQ(culled[c].rgb, all[c].rgb) << "channel " << c;
    EXPECT_EQ(tree[c].rgb, all[c].rgb) << "channel " << c;
  }
}

// BENCH.md: "every pixel is covered D times" — counted by the renderer, in every order.
TEST(LayersGenerator, EveryPixelIsCoveredDTimes) {
  for (auto order : {generators::SubmitOrder::random, generators::SubmitOrder::frontToBack,
                     generators::SubmitOrder::backToFront}) {
    generators::LayersParams p;
    p.layers = 3;
    p.order = order;
    p.width = 320;
    p.height = 200;
    RenderOptions o;
    o.width = p.width;
    o.height = p.height;
    o.threads = 2;
    o.debugView = RenderOptions::DebugView::overdraw;
    Renderer r(o);
    Image img;
    FrameStats stats;
    ASSERT_TRUE(r.render(generators::generateLayers(p), img, &stats).ok());
    EXPECT_EQ(stats.fragments, uint64_t(3) * 320 * 200) << generators::submitOrderName(order);
    // The overdraw palette's colour for 3: green (40, 200, 40), at every pixel.
    size_t wrong = 0;
    for (size_t i = 0; i < img.rgb.size(); i += 3)
      wrong += !(img.rgb[i] == 40 && img.rgb[i + 1] == 200 && img.rgb[i + 2] == 40);
    EXPECT_EQ(wrong, 0u) << generators::submitOrderName(order);
  }
}

}  // namespace
}  // namespace sv
