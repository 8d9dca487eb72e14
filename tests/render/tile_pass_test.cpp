// The frame as a list of passes (raster/tile_pass.h, docs/ARCHITECTURE.md "Passes"): each pass is
// prepared once a frame, drawn once into every tile where its stage says — after the tile's opaque
// triangles and before its translucent ones (surfaces, volumes), or after its last triangle
// (lights) — on a worker of the frame's pool, and adds its statistics once; across batches too,
// and with the same image for any thread count.
#include "raster/tile_pass.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "raster/framebuffer.h"
#include "support/raster_harness.h"

namespace sv {
namespace {

constexpr int kWidth = 128, kHeight = 64;           // two tiles side by side
constexpr int kProbeY = 10, kProbeX[2] = {10, 74};  // one probe pixel in each tile

// What a pass saw in one call.
struct Seen {
  std::string pass;
  int worker;
  uint16_t red;  // the tile's probe pixel, sample 0
};

// A pass that records its calls and what the tile's probe pixel held when it ran, and writes a
// mark (depth 0, full red) into the tile's pixel (1, 1) when `marks` is set.
class RecordingPass final : public raster::TilePass {
 public:
  RecordingPass(std::string name, raster::PassStage stage, std::vector<std::vector<Seen>>& log,
                std::mutex& mutex, bool marks = false)
      : name_(std::move(name)), stage_(stage), log_(log), mutex_(mutex), marks_(marks) {}

  raster::PassStage stage() const override { return stage_; }
  void prepare(const raster::PassFrame& frame) override {
    ++prepared;
    frame_ = frame;
  }
  void drawTile(const raster::TileTarget& tile) override {
    const int lx = kProbeX[tile.tileX] - tile.tileX * raster::kTileSize;
    const uint16_t red =
        tile.color[raster::FrameBuffer::colorOffset(lx, kProbeY, 0, frame_.samples, 0)];
    if (marks_)
      for (int s = 0; s < frame_.samples; ++s) {
        tile.depth[raster::FrameBuffer::depthOffset(1, 1, frame_.samples, s)] = 0;
        tile.color[raster::FrameBuffer::colorOffset(1, 1, 0, frame_.samples, s)] = 65535;
      }
    std::lock_guard lock(mutex_);
    log_[size_t(tile.tileY * 2 + tile.tileX)].push_back({name_, tile.worker, red});
  }
  void addStats(FrameStats& stats) const override { stats.freeForms += 1; }

  int prepared = 0;
  raster::PassFrame frame_;

 private:
  std::string name_;
  raster::PassStage stage_;
  std::vector<std::vector<Seen>>& log_;
  std::mutex& mutex_;
  bool marks_;
};

// Opaque grey triangles: many small ones away from the probes (several batches of 97), then a
// large one over both probes; last, a translucent red one over tile 0's probe only.
struct Scene {
  render::DrawPackets packets;
  shade::MaterialShading glass;
  shade::Environment environment;
};
void build(Scene& s, bool translucent) {
  render::DrawPackets& p = s.packets;
  for (int i = 0; i < 300; ++i) {
    const double x = 2 + (i * 37) % 120, y = 40 + (i * 13) % 20;
    test::addTriangle(p, test::pixelVertex(x, y, kWidth, kHeight, 0.5f),
                      test::pixelVertex(x + 4, y, kWidth, kHeight, 0.5f),
                      test::pixelVertex(x, y + 3, kWidth, kHeight, 0.5f));
  }
  test::addTriangle(p, test::pixelVertex(0, 0, kWidth, kHeight, 0.6f, 1, 0.3f, 0.3f, 0.3f),
                    test::pixelVertex(127, 0, kWidth, kHeight, 0.6f, 1, 0.3f, 0.3f, 0.3f),
                    test::pixelVertex(0, 30, kWidth, kHeight, 0.6f, 1, 0.3f, 0.3f, 0.3f));
  p.attributeLayout = geometry::AttributeLayout::of(1u << geometry::kAlpha);
  p.attributes.assign(p.vertices.size(), 1.0f);
  if (!translucent) return;
  s.glass.alpha = shade::AlphaUse::blend;
  const uint32_t base = uint32_t(p.vertices.size());
  for (const auto& [x, y] : {std::pair{0, 0}, std::pair{30, 0}, std::pair{0, 30}})
    p.vertices.push_back(test::pixelVertex(x, y, kWidth, kHeight, 0.2f, 1, 1, 0, 0));
  p.indices.insert(p.indices.end(), {base, base + 1, base + 2});
  render::DrawCall glass;
  glass.firstTriangle = uint32_t(p.indices.size() / 3 - 1);
  glass.triangleCount = 1;
  glass.cull = geometry::CullMode::none;
  glass.material = &s.glass;
  p.calls.push_back(glass);
  p.attributes.resize(p.vertices.size(), 0.5f);  // alpha ½
}

render::FrameSettings settings(const Scene& s) {
  render::FrameSettings f;
  f.width = kWidth;
  f.height = kHeight;
  f.shade = raster::ShadeMode::material;
  f.environment = &s.environment;
  f.batchTriangles = 97;  // four batches: the passes still run once per tile
  return f;
}

TEST(TilePass, EachStageRunsOnceATileInItsPlaceAcrossBatches) {
  for (const bool translucent : {false, true}) {
    Scene scene;
    build(scene, translucent);
    std::vector<std::vector<Seen>> log(2);
    std::mutex mutex;
    // Given out of stage order: the frame runs them by stage, a stage's in the order given.
    RecordingPass lights("lights", raster::PassStage::lights, log, mutex);
    RecordingPass surfaces("surfaces", raster::PassStage::surfaces, log, mutex);
    RecordingPass volumes("volumes", raster::PassStage::volumes, log, mutex);
    RecordingPass surfaces2("surfaces2", raster::PassStage::surfaces, log, mutex);
    render::FrameSettings s = settings(scene);
    s.passes = {&lights, &surfaces, &volumes, &surfaces2};
    FrameStats stats;
    test::renderQuadtree(scene.packets, s, 2, &stats);
    for (const RecordingPass* pass : {&lights, &surfaces, &volumes, &surfaces2}) {
      EXPECT_EQ(pass->prepared, 1);
      EXPECT_EQ(pass->frame_.width, kWidth);
      EXPECT_EQ(pass->frame_.height, kHeight);
      EXPECT_EQ(pass->frame_.samples, 1);
      ASSERT_NE(pass->frame_.pool, nullptr);
    }
    EXPECT_EQ(stats.freeForms, 4u);  // each pass's addStats, once
    for (int tile = 0; tile < 2; ++tile) {
      const std::vector<Seen>& seen = log[size_t(tile)];
      ASSERT_EQ(seen.size(), 4u) << "tile " << tile;
      EXPECT_EQ(seen[0].pass, "surfaces");
      EXPECT_EQ(seen[1].pass, "surfaces2");
      EXPECT_EQ(seen[2].pass, "volumes");
      EXPECT_EQ(seen[3].pass, "lights");
      for (const Seen& e : seen) EXPECT_TRUE(e.worker == 0 || e.worker == 1);
      // The opaque triangles are in before the first pass: its grey shows at the probe.
      const uint16_t grey = seen[0].red;
      EXPECT_NEAR(grey, 0.3 * 65535, 2);
      // The translucent triangle (tile 0 only) is drawn after the surfaces and volumes, before
      // the lights.
      EXPECT_EQ(seen[1].red, grey);
      EXPECT_EQ(seen[2].red, grey);
      if (translucent && tile == 0)
        EXPECT_GT(seen[3].red, grey + 10000);
      else
        EXPECT_EQ(seen[3].red, grey);
    }
  }
}

TEST(TilePass, WhatAPassDrawsIsTheSameForAnyThreadCount) {
  Scene scene;
  build(scene, true);
  std::vector<std::vector<Seen>> log(2);
  std::mutex mutex;
  RecordingPass marker("marker", raster::PassStage::surfaces, log, mutex, true);
  render::FrameSettings s = settings(scene);
  s.passes = {&marker};
  const test::Frame one = test::renderQuadtree(scene.packets, s, 1);
  // The mark: nearest depth and full red at pixel (1, 1) of both tiles.
  EXPECT_EQ(one.channel(1, 1, 0), 65535);
  EXPECT_EQ(one.channel(65, 1, 0), 65535);
  EXPECT_EQ(one.depth[1 * kWidth + 1], 0.0f);
  // (The translucent triangle, drawn after the mark, blends over it but cannot hide it.)
  for (int threads : {2, 8}) EXPECT_TRUE(test::renderQuadtree(scene.packets, s, threads) == one);
}

// The lights stage (TilePass::seeTile, FrameRenderer's wavefront): each tile is seen once, after
// its other passes, with its final depth; drawn once, after the nine tiles around it are seen — in a
// frame of one batch (the wavefront) and of several (the whole frame kept), for any thread count.
class OrderPass final : public raster::TilePass {
 public:
  struct Event {
    char kind;  // 'o' the tile's other passes done, 's' seen, 'd' drawn
    int tile;
  };
  OrderPass(raster::PassStage stage, std::vector<Event>& log, std::mutex& mutex)
      : stage_(stage), log_(log), mutex_(mutex) {}
  raster::PassStage stage() const override { return stage_; }
  void prepare(const raster::PassFrame& frame) override { samples_ = frame.samples; }
  // A surfaces pass marks its tile's pixel (2, 2) with a depth of its own; the lights pass checks
  // the mark of the tile it sees.
  static float mark(int tile) { return 0.25f + 0.01f * float(tile); }
  void seeTile(const raster::TileTarget& tile) override {
    const int t = tile.tileY * kTilesX + tile.tileX;
    EXPECT_EQ(tile.depth[raster::FrameBuffer::depthOffset(2, 2, samples_)], mark(t));
    record('s', t);
  }
  void drawTile(const raster::TileTarget& tile) override {
    const int t = tile.tileY * kTilesX + tile.tileX;
    if (stage_ == raster::PassStage::surfaces)
      for (int k = 0; k < samples_; ++k)
        tile.depth[raster::FrameBuffer::depthOffset(2, 2, samples_, k)] = mark(t);
    record(stage_ == raster::PassStage::surfaces ? 'o' : 'd', t);
  }
  void addStats(FrameStats&) const override {}

  static constexpr int kTilesX = 5, kTilesY = 4;

 private:
  void record(char kind, int tile) {
    std::lock_guard lock(mutex_);
    log_.push_back({kind, tile});
  }
  raster::PassStage stage_;
  std::vector<Event>& log_;
  std::mutex& mutex_;
  int samples_ = 1;
};

TEST(TilePass, TheLightsStageSeesATileOnceDrawnAndDrawsItOnceTheNineAroundItAreSeen) {
  constexpr int w = OrderPass::kTilesX * 64 - 20, h = OrderPass::kTilesY * 64 - 7;
  render::DrawPackets packets;
  for (int i = 0; i < 40; ++i) {
    const double x = (i * 53) % (w - 20), y = (i * 29) % (h - 20);
    test::addTriangle(packets, test::pixelVertex(x, y, w, h), test::pixelVertex(x + 19, y, w, h),
                      test::pixelVertex(x, y + 17, w, h));
  }
  for (const uint32_t batch : {1u << 18, 7u})
    for (const int threads : {1, 2, 5}) {
      const bool depthToSink = threads != 2;
      SCOPED_TRACE(testing::Message() << "batch " << batch << ", threads " << threads
                                      << ", depth to the sink " << depthToSink);
      std::vector<OrderPass::Event> log;
      std::mutex mutex;
      OrderPass lights(raster::PassStage::lights, log, mutex);
      OrderPass surfaces(raster::PassStage::surfaces, log, mutex);
      render::FrameSettings s;
      s.width = w;
      s.height = h;
      s.samples = 4;
      s.batchTriangles = batch;
      s.passes = {&lights, &surfaces};
      s.depthToSink = depthToSink;
      test::renderQuadtree(packets, s, threads);
      constexpr int tiles = OrderPass::kTilesX * OrderPass::kTilesY;
      std::vector<int> at[3];  // per kind, per tile: where in the log
      for (auto& a : at) a.assign(tiles, -1);
      for (size_t i = 0; i < log.size(); ++i) {
        const int kind = log[i].kind == 'o' ? 0 : log[i].kind == 's' ? 1 : 2;
        EXPECT_EQ(at[kind][size_t(log[i].tile)], -1)
            << log[i].kind << " twice, tile " << log[i].tile;
        at[kind][size_t(log[i].tile)] = int(i);
      }
      ASSERT_EQ(log.size(), size_t(3 * tiles));
      for (int t = 0; t < tiles; ++t) {
        EXPECT_LT(at[0][size_t(t)], at[1][size_t(t)])
            << "tile " << t << " seen before it was drawn";
        const int tx = t % OrderPass::kTilesX, ty = t / OrderPass::kTilesX;
        for (int y = std::max(0, ty - 1); y <= std::min(OrderPass::kTilesY - 1, ty + 1); ++y)
          for (int x = std::max(0, tx - 1); x <= std::min(OrderPass::kTilesX - 1, tx + 1); ++x) {
            const size_t u = size_t(y * OrderPass::kTilesX + x);
            EXPECT_LT(at[1][u], at[2][size_t(t)])
                << "tile " << t << " drawn before " << u << " was seen";
          }
      }
    }
}

}  // namespace
}  // namespace sv
