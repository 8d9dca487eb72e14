// Display channels (SPEC §9): a centred channel is the classic view bit for bit; abutting channels
// meet without a gap or an overlap; statistics are per channel; any thread count gives the same
// bytes; terrain on an asymmetric channel meets the ground where the polygons' projection says.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "core/quadric.h"
#include "raster/framebuffer.h"
#include "render/camera.h"
#include "render/shading_tables.h"
#include "render/terrains.h"
#include "support/test_scenes.h"
#include "synthvis/formats.h"
#include "synthvis/generators.h"
#include "synthvis/render.h"
#include "synthvis/terrain.h"

namespace sv {
namespace {

// The camera at the origin looking down −z, no light, black background.
scene::Scene unlitScene() {
  scene::Scene s = tests::emptyScene();
  s.materials.push_back({});
  s.materials[0].unlit = true;
  s.materials[0].doubleSided = true;
  return s;
}

// A white quad o + s·e1 + t·e2, s, t ∈ [0, 1].
void addQuad(scene::Scene& s, Vec3 o, Vec3 e1, Vec3 e2) {
  scene::Mesh m;
  m.positions = {o, o + e1, o + e1 + e2, o + e2};
  m.indices = {0, 1, 2, 0, 2, 3};
  m.material = 0;
  s.meshes.push_back(m);
  s.instances.push_back({int(s.meshes.size()) - 1, Mat4{}});
}

std::vector<Image> renderChannels(const scene::Scene& s, int threads,
                                  std::vector<FrameStats>* stats = nullptr, int samples = 1) {
  RenderOptions o;
  o.threads = threads;
  o.samples = samples;
  Renderer r(o);
  std::vector<Image> images;
  const Status st = r.renderChannels(s, images, stats);
  EXPECT_TRUE(st.ok()) << st.error().str();
  return images;
}

bool lit(const Image& im, int x, int y) { return im.pixel(x, y)[0] > 127; }

TEST(Channels, ACentredChannelIsTheClassicViewBitForBit) {
  for (scene::Scene s : {formats::demoScene(), tests::smallTerrain()}) {
    RenderOptions o;
    o.width = 160;
    o.height = 112;
    o.threads = 2;
    Image classic;
    ASSERT_TRUE(Renderer(o).render(s, classic));
    scene::Channel c;
    c.width = o.width;
    c.height = o.height;
    s.channels = {c};
    const render::FrameCamera a = render::chooseCamera(s, o).value();
    const render::FrameCamera b = render::channelCamera(s, o, c).value();
    EXPECT_EQ(a.view, b.view);
    EXPECT_EQ(a.projection, b.projection);
    std::vector<Image> images;
    ASSERT_TRUE(Renderer(o).renderChannels(s, images));
    ASSERT_EQ(images.size(), 1u);
    EXPECT_EQ(images[0].rgb, classic.rgb);
  }
}

// Two channels abutting at the camera's x = 0 plane (left: −45° … 0°, right: 0° … 45°). A polygon
// whose edge lies in that plane covers the whole of one channel, its last or first column
// included, and nothing of the other.
TEST(Channels, AnEdgeInTheSharedPlaneEndsExactlyAtTheBoundary) {
  for (int side : {-1, 1}) {
    scene::Scene s = unlitScene();
    // x from 0 to 100·side, y ±100, at depth 10: facing the camera either way (double-sided).
    addQuad(s, {0, -100, -10}, {100.0f * side, 0, 0}, {0, 200, 0});
    s.channels = scene::arcChannels(2, 90, 64, 48);
    const std::vector<Image> im = renderChannels(s, 2);
    ASSERT_EQ(im.size(), 2u);
    const Image& covered = im[side < 0 ? 0 : 1];
    const Image& empty = im[side < 0 ? 1 : 0];
    for (int y = 0; y < 48; ++y)
      for (int x = 0; x < 64; ++x) {
        ASSERT_TRUE(lit(covered, x, y)) << "side " << side << ": gap at " << x << ", " << y;
        ASSERT_FALSE(lit(empty, x, y)) << "side " << side << ": overlap at " << x << ", " << y;
      }
  }
}

// The covered rows of column x, as [first, last] (first > last when none), and their centre.
struct RowRun {
  int first = 1 << 20, last = -1;
  double centre() const { return 0.5 * (first + last) + 0.5; }
  bool empty() const { return first > last; }
};
RowRun runOf(const Image& im, int x) {
  RowRun r;
  for (int y = 0; y < im.height; ++y)
    if (lit(im, x, y)) r.first = std::min(r.first, y), r.last = std::max(r.last, y);
  return r;
}

// The least-squares line through the runs' centres of `columns`, evaluated at raster x = `at`.
double fitAt(const Image& im, const std::vector<int>& columns, double at) {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (int x : columns) {
    const RowRun r = runOf(im, x);
    EXPECT_FALSE(r.empty()) << "column " << x;
    const double cx = x + 0.5, cy = r.centre();
    n += 1, sx += cx, sy += cy, sxx += cx * cx, sxy += cx * cy;
  }
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  return (sy - slope * sx) / n + slope * at;
}

// A thin strip along y = x + 0.5 at depth 10 crosses the boundary of two abutting channels. It is
// one line: its rows in the left channel's last column and the right one's first touch or
// overlap, and the line each channel draws, carried to the shared edge, lands on the same row
// there. A gap or overlap of one pixel between the frusta would move them apart by about a row.
TEST(Channels, AnObliqueStripCrossingTheBoundaryIsContinuous) {
  scene::Scene s = unlitScene();
  const float t = 0.3f;  // the strip's height, about 2.5 pixels at the boundary
  addQuad(s, {-2, -1.5f - 0.5f * t, -10}, {4, 4, 0}, {0, t, 0});
  s.channels = scene::arcChannels(2, 90, 64, 48);
  const std::vector<Image> im = renderChannels(s, 2);
  const RowRun a = runOf(im[0], 63), b = runOf(im[1], 0);
  ASSERT_FALSE(a.empty());
  ASSERT_FALSE(b.empty());
  EXPECT_GE(a.last + 1, b.first);
  EXPECT_GE(b.last + 1, a.first);
  const double left = fitAt(im[0], {58, 59, 60, 61, 62, 63}, 64.0);
  const double right = fitAt(im[1], {0, 1, 2, 3, 4, 5}, 0.0);
  EXPECT_NEAR(left, right, 0.35);
  // The strip rises to the right (image rows fall), in both channels.
  EXPECT_LT(runOf(im[0], 63).centre(), runOf(im[0], 56).centre());
  EXPECT_LT(runOf(im[1], 7).centre(), runOf(im[1], 0).centre());
}

TEST(Channels, StatisticsAndSizesArePerChannel) {
  scene::Scene s = unlitScene();
  addQuad(s, {-1, -1, -10}, {2, 0, 0}, {0, 2, 0});  // straight ahead: the middle channel only
  s.channels = scene::arcChannels(3, 150, 64, 48);
  s.channels[2].width = 40;
  s.channels[2].height = 30;
  std::vector<FrameStats> stats;
  const std::vector<Image> im = renderChannels(s, 2, &stats);
  ASSERT_EQ(im.size(), 3u);
  ASSERT_EQ(stats.size(), 3u);
  EXPECT_EQ(im[0].width, 64);
  EXPECT_EQ(im[2].width, 40);
  EXPECT_EQ(im[2].height, 30);
  EXPECT_EQ(stats[0].drawn, 0u);
  EXPECT_EQ(stats[1].drawn, 2u);
  EXPECT_EQ(stats[2].drawn, 0u);
  EXPECT_EQ(stats[0].culledOutside, 2u);
  EXPECT_GT(stats[1].fragments, 0u);
  EXPECT_EQ(stats[2].fragments, 0u);
  const Image m = mosaic(im);
  EXPECT_EQ(m.width, 64 + 64 + 40);
  EXPECT_EQ(m.height, 48);
}

TEST(Channels, ThreeChannelsGiveTheSameBytesOnOneAndTwoThreads) {
  for (scene::Scene s : {formats::demoScene(), tests::smallTerrain()}) {
    s.channels = scene::arcChannels(3, 150, 96, 64);
    s.channels[0].offset = {-0.2f, 0.1f, 0};
    s.channels[2].pitchDegrees = 8;
    s.channels[2].rollDegrees = -5;
    const std::vector<Image> one = renderChannels(s, 1, nullptr, 4);
    const std::vector<Image> two = renderChannels(s, 2, nullptr, 4);
    ASSERT_EQ(one.size(), 3u);
    ASSERT_EQ(two.size(), 3u);
    for (size_t i = 0; i < 3; ++i) EXPECT_EQ(one[i].rgb, two[i].rgb) << "channel " << i;
  }
}

// Yaw right turns the view to the right: a quad 50° to the right of the camera's view is seen in
// the middle of a channel with yaw 50.
TEST(Channels, YawPositiveLooksToTheRight) {
  scene::Scene s = unlitScene();
  const float a = 50 * std::numbers::pi_v<float> / 180;
  const Vec3 at{10 * std::sin(a), 0, -10 * std::cos(a)};
  addQuad(s, at + Vec3{-0.3f, -0.3f, 0}, {0.6f, 0, 0}, {0, 0.6f, 0});
  scene::Channel c;
  c.yawDegrees = 50;
  c.width = 32;
  c.height = 32;
  s.channels = {c};
  const std::vector<Image> im = renderChannels(s, 1);
  EXPECT_TRUE(lit(im[0], 16, 16));
  c.yawDegrees = -50;
  s.channels = {c};
  EXPECT_FALSE(lit(renderChannels(s, 1)[0], 16, 16));
}

// The terrain pass casts its rays through an asymmetric, turned channel's pixels: where it leaves
// a depth, the point the polygons' projection puts at that pixel and depth (the inverse of
// projection · view, through Mat4::frustum) lies on the ground.
TEST(Channels, TerrainOnAnAsymmetricChannelMeetsTheGroundWhereTheProjectionSays) {
  const scene::Scene s = tests::smallTerrain();
  RenderOptions o;
  o.threads = 1;
  scene::Channel c;
  c.yawDegrees = 20;
  c.pitchDegrees = -5;
  c.offset = {3, -2, 1};
  c.frustum = scene::ChannelFrustum{-10, 45, -35, 4};
  c.width = o.width = 192;
  c.height = o.height = 128;
  const render::FrameCamera camera = render::channelCamera(s, o, c).value();
  render::ShadingTables shading;
  render::buildShading(s, o, camera.view, shading);
  terrain::TerrainPass pass;
  const EyeRays rays = render::eyeRays(camera);
  pass.setTerrains(render::terrainDraws(s, rays, shading, o), rays, shading.environment);
  pass.prepare(raster::PassFrame{o.width, o.height, 1, nullptr, nullptr});
  std::vector<float> depth(raster::kTileSize * raster::kTileSize, 1.0f);
  std::vector<uint16_t> color(raster::kTileSize * raster::kTileSize * 3, 0);
  const int tx = 1, ty = 1;
  pass.drawTile({tx, ty, depth.data(), color.data(), 0});
  Mat4d clipToWorld;
  const Mat4 pv = camera.projection * camera.view;
  for (int r = 0; r < 4; ++r)
    for (int k = 0; k < 4; ++k) clipToWorld.m[r][k] = pv.m[k][r];
  clipToWorld = clipToWorld.inverse().value();
  int checked = 0;
  for (int ly = 0; ly < raster::kTileSize; ly += 7)
    for (int lx = 0; lx < raster::kTileSize; lx += 7) {
      const float z = depth[raster::FrameBuffer::depthOffset(lx, ly)];
      if (!(z < 1.0f)) continue;
      const double px = tx * 64 + lx + 0.5, py = ty * 64 + ly + 0.5;
      const Vec3d w =
          clipToWorld.transformPoint({2 * px / o.width - 1, 1 - 2 * py / o.height, 2.0 * z - 1});
      const std::optional<TerrainHeight> h = terrainHeight(s, w.x, w.y, w.z);
      ASSERT_TRUE(h.has_value());
      EXPECT_NEAR(h->above, 0.0, 0.5) << "pixel " << px << ", " << py;
      ++checked;
    }
  EXPECT_GT(checked, 30);
}

}  // namespace
}  // namespace sv
