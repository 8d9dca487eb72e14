// Distortion correction the seeds' way (SPEC §12; issue 34 method (a), render/warped.h): a display
// drawn through its sub-frustum plan, every cell a view of its own. A flat display (one cell) draws
// the channel's own image, for polygons, terrain, free forms and volumes alike; on the cylinder
// rig, stripes bounded by planes through the eye land on every pixel as the exact display mapping
// says; every valid pixel is drawn (no crack), invalid ones are black; any thread count gives the
// same bytes.
#include "render/warped.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "display/geometry.h"
#include "display/subfrustum.h"
#include "render/camera.h"
#include "render/correction.h"
#include "render/view_renderer.h"
#include "support/temp_dir.h"
#include "support/test_scenes.h"
#include "synthvis/display.h"
#include "synthvis/formats.h"
#include "synthvis/generators.h"
#include "synthvis/render.h"

namespace sv {
namespace {

constexpr double kToRadians = std::numbers::pi / 180;

// The direction table of a pinhole camera turned by `o` with window `w`: a flat display.
display::DirectionTable pinholeTable(const display::Orientation& o, const display::Window& w,
                                     int width, int height) {
  const display::Rotation r = display::rotationOf(o);
  const double l = std::tan(w.leftDegrees * kToRadians), rt = std::tan(w.rightDegrees * kToRadians);
  const double d = std::tan(w.downDegrees * kToRadians), u = std::tan(w.upDegrees * kToRadians);
  display::DirectionTable t;
  t.width = width;
  t.height = height;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const double bx = l + (x + 0.5) / width * (rt - l), by = u - (y + 0.5) / height * (u - d);
      const Vec3d v{r.m[0][0] * bx + r.m[0][1] * by - r.m[0][2],
                    r.m[1][0] * bx + r.m[1][1] * by - r.m[1][2],
                    r.m[2][0] * bx + r.m[2][1] * by - r.m[2][2]};
      t.directions.push_back(normalize(v));
      t.valid.push_back(1);
    }
  return t;
}

// The display through `plan`, gamma-encoded, with the renderer's default camera of `scene`.
Image renderWarped(const scene::Scene& scene, RenderOptions o, const display::SubFrustumPlan& plan,
                   const std::vector<uint8_t>& valid, render::SubFrustumStats* cellStats = nullptr,
                   FrameStats* statsOut = nullptr, Vec3d eye = {0, 0, 0}) {
  o.width = plan.width;
  o.height = plan.height;
  render::SubFrustumRenderer renderer(o);
  const Result<render::FrameCamera> base = render::chooseCamera(scene, o);
  EXPECT_TRUE(base.ok());
  output::LinearImage linear;
  FrameStats stats;
  const Status s =
      renderer.render(scene, o, base.value(), eye, plan, valid, linear, stats, cellStats);
  EXPECT_TRUE(s.ok()) << s.error().str();
  Image image;
  output::prepareImage(o.width, o.height, image);
  output::encodeRows(linear, renderer.gamma(), 0, o.height, image);
  if (statsOut) *statsOut = stats;
  return image;
}

struct Difference {
  int differing = 0;  // pixels with any channel differing
  int maxCode = 0;    // the largest difference of a channel, 8-bit codes
};
Difference compare(const Image& a, const Image& b) {
  Difference d;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      int m = 0;
      for (int c = 0; c < 3; ++c) m = std::max(m, std::abs(a.pixel(x, y)[c] - b.pixel(x, y)[c]));
      d.differing += m > 0;
      d.maxCode = std::max(d.maxCode, m);
    }
  return d;
}

TEST(SubFrusta, AFlatDisplayDrawsTheChannelsImage) {
  // One cell whose map is the channel's pinhole: the same image as the channel, but for pixels
  // where the two projections' float roundings put an edge on different sides of a sample.
  const display::Orientation o{20, -5, 3};
  const display::Window w{-25, 30, -18, 15};
  const int width = 160, height = 112;
  const display::SubFrustumPlan plan = display::planSubFrusta(pinholeTable(o, w, width, height));
  ASSERT_EQ(plan.cells.size(), 1u);
  generators::VolumeParams vp;
  const std::vector<std::pair<const char*, scene::Scene>> scenes = {
      {"demo", formats::demoScene()},
      {"terrain", tests::smallTerrain()},
      {"free forms", generators::generateFreeFormOne()},
      {"volume", generators::generateVolume(vp)}};
  for (const auto& [name, s] : scenes) {
    RenderOptions opt;
    opt.threads = 2;
    opt.samples = 4;
    scene::Scene channelScene = s;
    scene::Channel c;
    c.width = width;
    c.height = height;
    c.yawDegrees = float(o.yawDegrees), c.pitchDegrees = float(o.pitchDegrees);
    c.rollDegrees = float(o.rollDegrees);
    c.frustum = scene::ChannelFrustum{float(w.leftDegrees), float(w.rightDegrees),
                                      float(w.downDegrees), float(w.upDegrees)};
    channelScene.channels = {c};
    std::vector<Image> channel;
    ASSERT_TRUE(Renderer(opt).renderChannels(channelScene, channel));
    const Image warped = renderWarped(s, opt, plan, {});
    const Difference d = compare(channel[0], warped);
    EXPECT_LE(d.differing, width * height / 100) << name;  // under 1 %
    EXPECT_LE(d.maxCode, 96) << name;
    std::printf("%s: %d of %d pixels differ, by up to %d codes\n", name, d.differing,
                width * height, d.maxCode);
  }
}

// Vertical stripes 6° wide around the eye on a cylinder of radius 2, alternately white and black;
// their edges lie in planes through the eye, so what a direction shows depends on its azimuth alone.
scene::Scene stripes() {
  // The camera at the origin looking down −z: the display's eye frame is its eye space.
  scene::Scene s = tests::emptyScene(200, {0.5f, 0, 0});
  s.materials.resize(2);
  s.materials[0].unlit = s.materials[1].unlit = true;
  s.materials[0].doubleSided = s.materials[1].doubleSided = true;
  s.materials[0].baseColor = {1, 1, 1};
  s.materials[1].baseColor = {0, 0, 0};
  for (int k = 0; k < 60; ++k) {
    const double a0 = (k * 6 - 180) * kToRadians, a1 = ((k + 1) * 6 - 180) * kToRadians;
    const auto at = [](double a, float y) {
      return Vec3{float(2 * std::sin(a)), y, float(-2 * std::cos(a))};
    };
    scene::Mesh m;
    m.positions = {at(a0, -3), at(a1, -3), at(a1, 3), at(a0, 3)};
    m.indices = {0, 1, 2, 0, 2, 3};
    m.material = k % 2;
    s.meshes.push_back(m);
    s.instances.push_back({int(s.meshes.size()) - 1, Mat4{}});
  }
  return s;
}

// The stripe (stripes()'s facet k, between the vertical edges at azimuths 6k − 180° and 6k − 174°
// on the radius-2 circle) that the ray from `eye` along `d` meets, and the sine of the angle from d
// to the nearer of that facet's two edge planes (each through the eye and an edge).
struct StripeHit {
  int k = -1;
  double toEdge = 0;
};
StripeHit stripeOf(Vec3d eye, Vec3d d) {
  const auto corner = [](int k) {
    const double a = (k * 6 - 180) * kToRadians;
    return Vec3d{2 * std::sin(a), 0, -2 * std::cos(a)};
  };
  for (int k = 0; k < 60; ++k) {
    const Vec3d p = corner(k), q = corner(k + 1), e = q - p;
    // eye + t·d = p + u·e in the xz plane.
    const double det = d.x * -e.z - d.z * -e.x;
    if (std::abs(det) < 1e-15) continue;
    const double rx = p.x - eye.x, rz = p.z - eye.z;
    const double t = (rx * -e.z - rz * -e.x) / det, u = (d.x * rz - d.z * rx) / det;
    if (!(t > 0) || u < 0 || u > 1) continue;
    double toEdge = 1;
    for (const Vec3d& c : {p, q}) {
      const Vec3d n = normalize(cross(c - eye, Vec3d{0, 1, 0}));
      toEdge = std::min(toEdge, std::abs(dot(normalize(d), n)));
    }
    return {k, toEdge};
  }
  return {};
}

TEST(SubFrusta, StripesOnTheCylinderRigLandWhereTheDisplayMappingSays) {
  // The eye at the rig's centre, then moved as a tracked head moves (dynamic correction: a new
  // direction table, a new plan, the cells' cameras moved to the new eye).
  for (const Vec3 eye : {Vec3{0, 0, 0}, Vec3{0.3f, 0.1f, -0.2f}}) {
    display::CylinderRig rig = display::threeProjectorCylinder(3, 10, 320, 200);
    rig.eye = eye;
    const Vec3d eyed{eye.x, eye.y, eye.z};
    const scene::Scene s = stripes();
    RenderOptions o;
    o.threads = 2;
    for (int p = 0; p < 3; ++p) {
      const display::DirectionTable table = display::directionTable(rig.geometry(p));
      const display::SubFrustumPlan plan = display::planSubFrusta(table);
      render::SubFrustumStats cs;
      const Image image = renderWarped(s, o, plan, table.valid, &cs, nullptr, eyed);
      EXPECT_EQ(cs.cells, int(plan.cells.size()));
      // A pixel centre's exact direction decides its stripe, unless the map's error (its
      // residual, at most 0.1 px) and the vertices' rounding could move the edge across it:
      // pixels whose direction lies within 1.4 pixel angles of an edge are left out.
      const display::Window& lens = rig.projectors[size_t(p)].lens;
      const double pixelAngle = 1.4 * (lens.rightDegrees - lens.leftDegrees) / 320 * kToRadians;
      int checked = 0, wrong = 0;
      for (int y = 0; y < table.height; ++y)
        for (int x = 0; x < table.width; ++x) {
          const size_t i = table.index(x, y);
          const uint8_t* px = image.pixel(x, y);
          if (!table.valid[i]) {
            EXPECT_TRUE(px[0] == 0 && px[1] == 0 && px[2] == 0) << x << "," << y;
            continue;
          }
          const StripeHit hit = stripeOf(eyed, table.directions[i]);
          if (hit.k < 0 || hit.toEdge < pixelAngle) continue;
          ++checked;
          wrong += hit.k % 2 == 0 ? !(px[0] == 255 && px[1] == 255 && px[2] == 255)
                                  : !(px[0] == 0 && px[1] == 0 && px[2] == 0);
        }
      EXPECT_EQ(wrong, 0) << "projector " << p << ", eye " << eye.x;
      EXPECT_GT(checked, 320 * 200 / 2) << "projector " << p << ", eye " << eye.x;
    }
  }
}

TEST(SubFrusta, EveryValidPixelIsDrawnOnceInAnyThreadCount) {
  // A white box around the eye, anti-aliased: every valid pixel's samples all white (a crack
  // between cells would let the background through), invalid pixels black.
  scene::Scene s = tests::emptyScene(200, {0, 0, 1});
  s.materials.resize(1);
  s.materials[0].unlit = true;
  s.materials[0].doubleSided = true;
  scene::Mesh box;
  for (int i = 0; i < 8; ++i)
    box.positions.push_back(
        {(i & 1) ? 10.0f : -10.0f, (i & 2) ? 10.0f : -10.0f, (i & 4) ? 10.0f : -10.0f});
  box.indices = {0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1,
                 2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3};
  box.material = 0;
  s.meshes.push_back(box);
  s.instances.push_back({0, Mat4{}});
  display::CylinderRig rig = display::threeProjectorCylinder(3, 10, 256, 160);
  rig.screen.maxHeight = 0.8;  // cut the screen: the projector's top rows miss it
  const display::DirectionTable table = display::directionTable(rig.geometry(1));
  const display::SubFrustumPlan plan = display::planSubFrusta(table);
  int invalid = 0;
  RenderOptions o;
  o.samples = 4;
  std::vector<Image> images;
  for (int threads : {1, 2, 5}) {
    o.threads = threads;
    images.push_back(renderWarped(s, o, plan, table.valid));
  }
  for (int y = 0; y < table.height; ++y)
    for (int x = 0; x < table.width; ++x) {
      const uint8_t* px = images[0].pixel(x, y);
      const bool valid = table.valid[table.index(x, y)] != 0;
      invalid += !valid;
      const int want = valid ? 255 : 0;
      ASSERT_TRUE(px[0] == want && px[1] == want && px[2] == want) << x << "," << y;
    }
  EXPECT_GT(invalid, 0);
  EXPECT_EQ(images[0].rgb, images[1].rgb);
  EXPECT_EQ(images[0].rgb, images[2].rgb);
}

// Issue 61: a display's plans are made the first frame and kept — the next frames make none and
// draw the same bytes; a copy of the display's setup starts without them.
TEST(SubFrusta, ADisplaysPlansAreMadeOnceAndKept) {
  scene::Scene s = tests::emptyScene(200, {0, 0, 1});
  s.materials.resize(1);
  s.materials[0].baseColor = {0.8f, 0.5f, 0.2f, 1};
  scene::Mesh quad;
  quad.positions = {{-30, -5, -40}, {30, -5, -40}, {30, 8, -40}, {-30, 8, -40}};
  quad.indices = {0, 1, 2, 0, 2, 3};
  quad.material = 0;
  s.meshes.push_back(quad);
  s.instances.push_back({0, Mat4{}});
  const Display display = Display::cylinder(256, 160);
  RenderOptions o;
  o.threads = 2;
  Renderer r(o);
  std::vector<std::vector<Image>> frames(3);
  for (size_t f = 0; f < frames.size(); ++f) {
    std::vector<DisplayStats> stats;
    ASSERT_TRUE(r.renderDisplay(s, display, frames[f], nullptr, &stats).ok());
    ASSERT_EQ(stats.size(), 3u);
    for (const DisplayStats& c : stats) {
      EXPECT_GT(c.cells, 1);
      if (f == 0)
        EXPECT_GT(c.planMs, 0.0) << "the first frame plans";
      else
        EXPECT_EQ(c.planMs, 0.0) << "frame " << f << " planned again";
    }
    for (size_t i = 0; i < frames[f].size(); ++i) EXPECT_EQ(frames[f][i].rgb, frames[0][i].rgb);
  }
  const render::ProjectorSetup copy = display.setup().projectors[0];
  double madeMs = 0;
  display::SubFrustumOptions so;
  so.znear = s.cameras.empty() ? so.znear : s.cameras[0].znear;
  EXPECT_NE(copy.plan.of(copy.table, so, madeMs), nullptr);
  EXPECT_GT(madeMs, 0.0) << "a copied setup kept the plan";
}

TEST(SubFrusta, TheLightCullDrawsEveryCellAsItsOwnPassOverEveryLightWould) {
  // Light points all around the eye at many distances, some large (a splat reaching well into the
  // neighbouring cells), and a star field: each cell of the cylinder rig's centre projector drawn
  // by the renderer — its lights culled once for all cells — against the same cell drawn alone,
  // its light pass projecting every light. The same bytes.
  scene::Scene s = tests::emptyScene(500, {0, 0, 0});
  s.lightAppearances.resize(1);
  s.lightSettings.maxSize = 24;
  uint32_t seed = 7;
  auto next = [&seed] {  // a small LCG: the test needs spread, not statistics
    seed = seed * 1664525u + 1013904223u;
    return float(seed >> 8) / float(1u << 24);
  };
  for (int i = 0; i < 3000; ++i) {
    const float azimuth = 2 * std::numbers::pi_v<float> * next();
    const float elevation = 0.8f * (next() - 0.5f), range = 3 + 300 * next() * next();
    s.lightPoints.push_back(
        {Vec3{std::sin(azimuth), std::tan(elevation), -std::cos(azimuth)} * range, 0, next(), -1});
  }
  for (int i = 0; i < 2000; ++i) {
    const Vec3 d{next() - 0.5f, next() - 0.5f, next() - 0.5f};
    s.stars.stars.push_back({normalize(d), 6 * next(), {1, 1, 1}});
  }
  const display::CylinderRig rig = display::threeProjectorCylinder(3, 10, 320, 200);
  const display::DirectionTable table = display::directionTable(rig.geometry(1));
  const display::SubFrustumPlan plan = display::planSubFrusta(table);
  const Vec3d eye{rig.eye.x, rig.eye.y, rig.eye.z};
  RenderOptions o;
  o.samples = 4;
  o.width = plan.width;
  o.height = plan.height;
  o.threads = 2;
  render::SubFrustumRenderer renderer(o);
  const render::FrameCamera base = render::chooseCamera(s, o).value();
  output::LinearImage culled;
  FrameStats stats;
  ASSERT_TRUE(renderer.render(s, o, base, eye, plan, {}, culled, stats).ok());
  RenderOptions single = o;
  single.threads = 1;
  render::ViewRenderer alone(single);
  int cells = 0, differing = 0;
  uint64_t drawn = 0;
  for (const display::SubFrustumCell& cell : plan.cells) {
    if (!cell.fitted) continue;
    RenderOptions co = single;
    co.width = cell.x1 - cell.x0;
    co.height = cell.y1 - cell.y0;
    output::LinearImage image;
    FrameStats cs;
    ASSERT_TRUE(alone.renderLinear(s, co, render::cellCamera(base, cell, eye), image, cs).ok());
    drawn += cs.lightsDrawn;
    for (int y = 0; y < co.height; ++y)
      for (int x = 0; x < co.width; ++x)
        for (int c = 0; c < 3; ++c)
          differing +=
              image.rgb[(size_t(y) * size_t(co.width) + size_t(x)) * 3 + size_t(c)] !=
              culled.rgb[(size_t(cell.y0 + y) * size_t(o.width) + size_t(cell.x0 + x)) * 3 +
                         size_t(c)];
    ++cells;
  }
  EXPECT_GT(cells, 16);
  EXPECT_GT(drawn, 1000u);  // lights were drawn, many of them in more than one cell
  EXPECT_EQ(stats.lightsDrawn, drawn);
  EXPECT_EQ(differing, 0);
  // The cull is the point: the cells' passes considered far fewer lights than cells × lights.
  EXPECT_LT(stats.lightPoints, uint64_t(cells) * 5000 / 10);
}

}  // namespace
}  // namespace sv

namespace sv {
namespace {

// The edge-spread function of a display: for every valid pixel within 3 px of a stripe edge (the
// stripes() scene), its signed distance to the edge in display pixels along the row (positive on
// the white side) and its linear value (0 black … 1 white); averaged in bins of 0.05 px, the 10 %
// and 90 % crossings give the edge's rise in pixels.
double edgeRise(const display::DirectionTable& t, const output::LinearImage& image) {
  constexpr int kBins = 120;  // −3 … 3 px
  std::vector<double> sum(kBins, 0), count(kBins, 0);
  for (int y = 0; y < t.height; ++y)
    for (int x = 1; x + 1 < t.width; ++x) {
      const size_t i = t.index(x, y);
      if (!t.valid[i] || !t.valid[i - 1] || !t.valid[i + 1]) continue;
      const Vec3d d = t.directions[i];
      const double azimuth = std::atan2(d.x, -d.z) / kToRadians;
      const int k = int(std::lround((azimuth + 180) / 6));  // the nearest edge: stripes k−1 | k
      const double e = (k * 6 - 180) * kToRadians;
      // The edge's plane through the eye, its normal toward stripe k (increasing azimuth).
      Vec3d n{std::cos(e), 0, std::sin(e)};
      if (k % 2 != 0) n = n * -1.0;  // stripe k black: toward stripe k − 1, the white one
      const double s = dot(d, n);
      const double g = 0.5 * (dot(t.directions[i + 1], n) - dot(t.directions[i - 1], n));
      if (!(std::abs(g) > 0)) continue;
      const double px = s / std::abs(g);
      const int bin = int(std::floor((px + 3) / 6 * kBins));
      if (bin < 0 || bin >= kBins) continue;
      sum[size_t(bin)] += image.rgb[3 * i] / 65535.0;
      count[size_t(bin)] += 1;
    }
  auto crossing = [&](double level) {
    double prev = 0, prevX = -3;
    for (int b = 0; b < kBins; ++b) {
      if (count[size_t(b)] == 0) continue;
      const double v = sum[size_t(b)] / count[size_t(b)], x = -3 + (b + 0.5) * 6 / kBins;
      if (v >= level) return prevX + (level - prev) / (v - prev) * (x - prevX);
      prev = v, prevX = x;
    }
    return 3.0;
  };
  return crossing(0.9) - crossing(0.1);
}

TEST(SubFrusta, AreSharperThanAFlatViewResampled) {
  // docs/quality.md, "Distortion correction": the rig's centre projector, 16 samples a pixel, the
  // same scene through method (a) and through method (b)'s flat view (its own 16 samples a flat
  // pixel, at the display's finest angular pixel) resampled bilinear and bicubic.
  const display::CylinderRig rig = display::threeProjectorCylinder(3, 10, 640, 400);
  const display::DirectionTable table = display::directionTable(rig.geometry(1));
  const scene::Scene s = stripes();
  RenderOptions o;
  o.threads = 2;
  o.samples = 16;
  render::CorrectionRenderer renderer(o);
  const Result<render::FrameCamera> base = render::chooseCamera(s, o);
  ASSERT_TRUE(base.ok());
  double rise[3];
  for (int m = 0; m < 3; ++m) {
    render::CorrectedView view;
    view.table = &table;
    view.correction = m == 0   ? RenderOptions::Correction::subFrusta
                      : m == 1 ? RenderOptions::Correction::bilinear
                               : RenderOptions::Correction::bicubic;
    output::LinearImage out;
    FrameStats stats;
    DisplayStats cs;
    ASSERT_TRUE(render::renderCorrected(renderer, s, o, base.value(), view, out, stats, cs));
    rise[m] = edgeRise(table, out);
  }
  std::printf(
      "10-90 %% edge rise: sub-frusta %.3f px, resampled bilinear %.3f px, bicubic %.3f px\n",
      rise[0], rise[1], rise[2]);
  EXPECT_LT(rise[0], 1.0);
  EXPECT_LT(rise[0] * 1.15, rise[1]);
  EXPECT_LT(rise[0], rise[2]);
}

// Walls at 1.5, 4 and 20 m in three colours, over a grey floor: what a moved eye sees move.
scene::Scene parallaxWalls() {
  scene::Scene s = tests::emptyScene(200, {0.1f, 0.2f, 0.5f});
  const Vec3 colours[3] = {{0.9f, 0.2f, 0.1f}, {0.1f, 0.8f, 0.2f}, {0.9f, 0.9f, 0.2f}};
  const float depths[3] = {1.5f, 4, 20};
  for (int k = 0; k < 3; ++k) {
    scene::Material m;
    m.baseColor = {colours[k].x, colours[k].y, colours[k].z, 1};
    s.materials.push_back(m);
    const float z = -depths[k], w = 0.25f * depths[k], x = (k - 1) * 0.6f * depths[k];
    scene::Mesh quad;
    quad.positions = {{x - w, -0.3f * depths[k], z},
                      {x + w, -0.3f * depths[k], z},
                      {x + w, 0.25f * depths[k], z},
                      {x - w, 0.25f * depths[k], z}};
    quad.indices = {0, 1, 2, 0, 2, 3};
    quad.material = uint32_t(k);
    s.meshes.push_back(quad);
    s.instances.push_back({k, Mat4{}});
  }
  return s;
}

// Issue 61: the sub-frusta as a stage (one traversal and vertex stage in the cover's clip space,
// each cell's triangles taken to its own by one map) draws what every cell as a view of its own
// drew — the same pixels but where the two float paths put an edge on different sides of a
// sample — for every kind of primitive, with lights, on the cylinder rig's centre projector; and
// the same bytes for any thread count.
TEST(SubFrusta, TheStageDrawsWhatEachCellAsAViewOfItsOwnDrew) {
  const display::CylinderRig rig = display::threeProjectorCylinder(3, 10, 240, 150);
  const display::DirectionTable table = display::directionTable(rig.geometry(1));
  const display::SubFrustumPlan plan = display::planSubFrusta(table);
  generators::VolumeParams vp;
  std::vector<std::pair<const char*, scene::Scene>> scenes = {
      {"demo", formats::demoScene()},
      {"terrain", tests::smallTerrain()},
      {"free forms", generators::generateFreeFormOne()},
      {"volume", generators::generateVolume(vp)},
      {"walls", parallaxWalls()}};
  // Light points on the walls' scene, some large: their splats cross the cells' edges.
  scene::Scene& lit = scenes.back().second;
  lit.lightAppearances.push_back({});
  lit.lightAppearances[0].intensity = 2000;
  for (int k = 0; k < 400; ++k)
    lit.lightPoints.push_back(
        {{float(k % 40) * 0.5f - 10, -1.0f + float(k / 40) * 0.2f, -6.0f - float(k % 7)}, 0});
  const int pixels = table.width * table.height;
  for (const auto& [name, s] : scenes) {
    RenderOptions o;
    o.threads = 2;
    o.samples = 4;
    o.width = table.width;
    o.height = table.height;
    const Result<render::FrameCamera> base = render::chooseCamera(s, o);
    ASSERT_TRUE(base.ok());
    Image images[2];
    for (int stage = 0; stage < 2; ++stage) {
      render::SubFrustumRenderer r(o);
      r.useStage(stage == 1);
      output::LinearImage linear;
      FrameStats stats;
      ASSERT_TRUE(r.render(s, o, base.value(), {0, 0, 0}, plan, table.valid, linear, stats));
      output::prepareImage(o.width, o.height, images[stage]);
      output::encodeRows(linear, r.gamma(), 0, o.height, images[stage]);
    }
    const Difference d = compare(images[0], images[1]);
    std::printf("%s: %d of %d pixels differ between the stage and the cells' own views, by up to "
                "%d codes\n",
                name, d.differing, pixels, d.maxCode);
    EXPECT_LE(d.differing, pixels / 500) << name;  // under 0.2 %
    EXPECT_LE(d.maxCode, 64) << name;
  }
  // Any thread count: the same bytes.
  RenderOptions o;
  o.samples = 4;
  o.width = table.width;
  o.height = table.height;
  std::vector<std::vector<uint16_t>> frames;
  for (int threads : {1, 2, 5}) {
    o.threads = threads;
    render::SubFrustumRenderer r(o);
    output::LinearImage linear;
    FrameStats stats;
    ASSERT_TRUE(r.render(lit, o, render::chooseCamera(lit, o).value(), {0, 0, 0}, plan,
                         table.valid, linear, stats));
    frames.push_back(linear.rgb);
  }
  EXPECT_EQ(frames[0], frames[1]);
  EXPECT_EQ(frames[0], frames[2]);
}

// The frame's finish in the cells (each cell blended and put through the gamma table while in
// cache), or the cells resolved through the table straight into the image, blend inline, give
// the bytes of a blend and a gamma pass over the whole frame after.
TEST(SubFrusta, BlendedAndEncodedCellByCellAsOverTheWholeFrame) {
  const scene::Scene s = parallaxWalls();
  const render::DisplaySetup d = render::cylinderDisplay(200, 120);
  RenderOptions o;
  o.threads = 2;
  o.samples = 4;
  render::CorrectionRenderer renderer(o);
  const Result<render::FrameCamera> base = render::chooseCamera(s, o);
  ASSERT_TRUE(base.ok());
  for (const render::ProjectorSetup& p : d.projectors) {
    ASSERT_TRUE(p.blend.has_value());
    render::CorrectedView view;
    view.table = &p.table;
    view.blend = &*p.blend;
    view.eye = d.eye;
    output::LinearImage a, b;
    FrameStats stats;
    DisplayStats cs;
    Image fused, after;
    ASSERT_TRUE(render::renderCorrected(renderer, s, o, base.value(), view, a, stats, cs, &fused));
    ASSERT_TRUE(render::renderCorrected(renderer, s, o, base.value(), view, b, stats, cs));
    EXPECT_GT(cs.blendMs, 0.0) << "blended over the frame after";
    renderer.encode(b, o, after);
    EXPECT_EQ(a.rgb, b.rgb) << p.name;
    EXPECT_EQ(fused.rgb, after.rgb) << p.name;
    // Not kept in linear light: the cells resolve through the table into the image, blended as
    // they are drawn — the same bytes.
    output::LinearImage untouched;
    Image direct;
    ASSERT_TRUE(render::renderCorrected(renderer, s, o, base.value(), view, untouched, stats, cs,
                                        &direct, false));
    EXPECT_EQ(direct.rgb, after.rgb) << p.name;
  }
}

// Issue 61, dynamic correction: a frame for an eye moved from the design eye is drawn through the
// design plan's cells refitted for it — the same picture, pixel for pixel but at edges, as a
// display planned from scratch for that eye — and the refit is made once for an eye that stays.
TEST(SubFrusta, AMovedEyeIsDrawnThroughItsRefittedMapsAsThroughAPlanMadeForIt) {
  const scene::Scene s = parallaxWalls();
  RenderOptions o;
  o.threads = 2;
  o.samples = 4;
  const Display display = Display::cylinder(256, 160);
  DisplayView moved;
  moved.eyeOffset[0] = 0.12f, moved.eyeOffset[1] = 0.06f, moved.eyeOffset[2] = -0.10f;
  Renderer r(o);
  std::vector<Image> design, refitted, again;
  std::vector<DisplayStats> stats;
  ASSERT_TRUE(r.renderDisplay(s, display, design).ok());
  ASSERT_TRUE(r.renderDisplay(s, display, refitted, nullptr, &stats, moved).ok());
  for (const DisplayStats& c : stats) {
    EXPECT_GT(c.refitMs, 0.0) << "the moved eye refits";
    EXPECT_EQ(c.planMs, 0.0) << "the design plan is kept";
  }
  ASSERT_TRUE(r.renderDisplay(s, display, again, nullptr, &stats, moved).ok());
  for (size_t i = 0; i < stats.size(); ++i) {
    EXPECT_EQ(stats[i].refitMs, 0.0) << "an eye that stays is not refitted again";
    EXPECT_EQ(again[i].rgb, refitted[i].rgb);
  }
  // The reference: the rig with its eye moved, its tables and plans made from scratch.
  render::DisplaySetup fresh = render::cylinderDisplay(256, 160);
  fresh.rig->eye =
      fresh.rig->eye + Vec3{moved.eyeOffset[0], moved.eyeOffset[1], moved.eyeOffset[2]};
  fresh.eye = {fresh.rig->eye.x, fresh.rig->eye.y, fresh.rig->eye.z};
  for (size_t i = 0; i < fresh.projectors.size(); ++i)
    fresh.projectors[i].table = display::directionTable(fresh.rig->geometry(int(i)));
  render::CorrectionRenderer renderer(o);
  render::DisplayFrame frame;
  ASSERT_TRUE(render::renderDisplay(renderer, s, o, fresh, frame).ok());
  for (size_t i = 0; i < 3; ++i) {
    const Difference toFresh = compare(refitted[i], frame.images[i]);
    const Difference toDesign = compare(refitted[i], design[i]);
    const int pixels = refitted[i].width * refitted[i].height;
    std::printf(
        "projector %zu: %d of %d pixels differ from the plan made for the eye (max %d "
        "codes), %d from the design eye's frame\n",
        i, toFresh.differing, pixels, toFresh.maxCode, toDesign.differing);
    EXPECT_LT(toFresh.differing, pixels / 400) << "projector " << i;
    EXPECT_GT(toDesign.differing, pixels / 100) << "the eye's move shows (projector " << i << ")";
  }
}

// The half-resolution level's display: each pixel shows the direction the full display's 2 × 2
// block around it does (the same lens over fewer pixels), for the analytic rig and for the same
// rig read back from an MPCDI file (its warp sampled at the new centres).
TEST(SubFrusta, AScaledDisplaysPixelsShowTheirBlocksDirections) {
  const Display full = Display::cylinder(256, 160);
  tests::TempDir dir;
  const std::string path = dir.path("rig.mpcdi");
  ASSERT_TRUE(full.writeMpcdi(path).ok());
  const Result<Display> file = Display::readMpcdi(path);
  ASSERT_TRUE(file.ok()) << file.error().str();
  for (const Display* d : {&full, &file.value()}) {
    const Display half = d->scaled(2);
    ASSERT_EQ(half.projectorCount(), 3);
    for (int p = 0; p < 3; ++p) {
      EXPECT_EQ(half.projectorWidth(p), 128);
      EXPECT_EQ(half.projectorHeight(p), 80);
      const display::DirectionTable& t = half.setup().projectors[size_t(p)].table;
      const display::DisplayGeometry g = full.setup().rig->geometry(p);
      double worst = 0;
      int valid = 0;
      for (int y = 0; y < t.height; ++y)
        for (int x = 0; x < t.width; ++x) {
          if (!t.valid[t.index(x, y)]) continue;
          const std::optional<Vec3d> exact = display::viewDirection(g, 2 * x + 1, 2 * y + 1);
          ASSERT_TRUE(exact.has_value());
          worst = std::max(worst, angleBetween(*exact, t.directions[t.index(x, y)]));
          ++valid;
        }
      EXPECT_GT(valid, t.width * t.height / 2);
      EXPECT_LT(worst, d == &full ? 1e-6 : 1e-4) << "projector " << p;
      EXPECT_TRUE(half.setup().projectors[size_t(p)].blend.has_value());
    }
  }
}

// Pictures on the screen (the IG's test patterns): a panorama whose red code rises with azimuth
// and green with elevation, shown on the rig's projectors without their blend, gives every valid
// pixel the codes of its own direction.
TEST(DisplayPictures, EachProjectorPixelShowsThePanoramaInItsOwnDirection) {
  render::DisplaySetup d = render::cylinderDisplay(192, 120);
  for (render::ProjectorSetup& p : d.projectors) p.blend.reset();
  const display::PanoramaView view = render::displayPanorama(d, 0.5);
  EXPECT_GT(view.width, 360);  // 180° and the overlaps at half a degree
  // Pixels too fine for a picture of the field: coarser ones, at most kMaxRasterSize a side.
  const display::PanoramaView fine = render::displayPanorama(d, 1e-4);
  EXPECT_LE(std::max(fine.width, fine.height), kMaxRasterSize);
  EXPECT_GT(fine.width, kMaxRasterSize / 2);
  Image picture;
  output::prepareImage(view.width, view.height, picture);
  for (int y = 0; y < view.height; ++y)
    for (int x = 0; x < view.width; ++x) {
      uint8_t* px = picture.pixel(x, y);
      px[0] = uint8_t(255 * x / (view.width - 1));
      px[1] = uint8_t(255 * y / (view.height - 1));
      px[2] = 0;
    }
  core::ThreadPool pool(2);
  std::vector<Image> images;
  render::showPanorama(d, view, picture, output::GammaTable::srgb(), pool, images);
  ASSERT_EQ(images.size(), 3u);
  int checked = 0;
  for (size_t p = 0; p < 3; ++p) {
    const display::DirectionTable& t = d.projectors[p].table;
    for (int y = 0; y < t.height; y += 3)
      for (int x = 0; x < t.width; x += 3) {
        const uint8_t* px = images[p].pixel(x, y);
        if (!t.valid[t.index(x, y)]) {
          EXPECT_EQ(px[0] + px[1] + px[2], 0);
          continue;
        }
        const display::PanoramaPoint q = display::panoramaPoint(view, t.directions[t.index(x, y)]);
        const double red = 255 * (q.x - 0.5) / (view.width - 1);
        const double green = 255 * (q.y - 0.5) / (view.height - 1);
        ASSERT_NEAR(px[0], red, 2.5) << "projector " << p << " pixel " << x << ", " << y;
        ASSERT_NEAR(px[1], green, 2.5) << "projector " << p << " pixel " << x << ", " << y;
        ++checked;
      }
  }
  EXPECT_GT(checked, 3000);
}

// The overlay's patch: only the pixels whose directions fall in its rectangle change, each to
// v·scale + add as the two layers say.
TEST(DisplayPictures, AnOverlayChangesOnlyThePixelsUnderIt) {
  const render::DisplaySetup d = render::cylinderDisplay(192, 120);
  const display::PanoramaView view = render::displayPanorama(d, 0.5);
  const int x0 = view.width / 2 - 20, y0 = 10, w = 40, h = 20;
  const render::PanoramaPatch patch = render::panoramaPatch(d, view, x0, y0, w, h);
  ASSERT_EQ(patch.pixels.size(), 3u);
  EXPECT_TRUE(patch.pixels[0].empty()) << "the left projector sees no azimuth near 0";
  EXPECT_GT(patch.pixels[1].size(), size_t(w * h / 2));
  // Opaque 200 in the left half of the patch, untouched (×1 + 0) in the right.
  Image onBlack, onWhite;
  for (Image* layer : {&onBlack, &onWhite}) {
    output::prepareImage(w, h, *layer);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c)
          layer->pixel(x, y)[c] = x < w / 2 ? 200 : (layer == &onBlack ? 0 : 255);
  }
  std::vector<Image> images(3);
  for (size_t p = 0; p < 3; ++p) {
    output::prepareImage(192, 120, images[p]);
    std::fill(images[p].rgb.begin(), images[p].rgb.end(), uint8_t(50));
  }
  render::overlayPatch(patch, onBlack, onWhite, images);
  const display::DirectionTable& t = d.projectors[1].table;
  int opaque = 0, kept = 0;
  for (int y = 0; y < t.height; ++y)
    for (int x = 0; x < t.width; ++x) {
      const uint8_t v = images[1].pixel(x, y)[0];
      bool inLeft = false;
      if (t.valid[t.index(x, y)]) {
        const display::PanoramaPoint q = display::panoramaPoint(view, t.directions[t.index(x, y)]);
        const double px = std::floor(q.x) - x0, py = std::floor(q.y) - y0;
        inLeft = px >= 0 && px < w / 2 && py >= 0 && py < h;
      }
      EXPECT_EQ(v, inLeft ? 200 : 50) << x << ", " << y;
      (inLeft ? opaque : kept)++;
    }
  EXPECT_GT(opaque, 100);
  EXPECT_EQ(images[0].rgb, std::vector<uint8_t>(images[0].rgb.size(), 50));
}

}  // namespace
}  // namespace sv
