// Multi-level priority masking (SPEC §4, RASTER-NOTES "visibility"): on scenes given in a true
// front-to-back order without interpenetration it draws the Z-buffer's frame sample for sample, at
// every sample count, thread count and batching, while dropping hidden triangles and windows; the
// occupancy hierarchy itself marks and propagates as the SPEC says.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "geometry/vertex_stage.h"
#include "raster/occupancy.h"
#include "support/raster_harness.h"

namespace sv {
namespace {

using raster::Occupancy;
using render::DrawPackets;
using render::FrameSettings;

TEST(Occupancy, FourFullChildrenMakeTheirParentFullUpToTheTile) {
  Occupancy o;
  o.clear(1);
  EXPECT_FALSE(o.fullOrInside(2, 0, 0));
  // Three 32×32 quarters, then the last one block by block.
  o.markFull(5, 0, 0);
  o.markFull(5, 32, 0);
  o.markFull(5, 0, 32);
  EXPECT_TRUE(o.full(5, 32, 0));
  EXPECT_FALSE(o.full(6, 0, 0));
  EXPECT_TRUE(o.fullOrInside(2, 40, 8));  // inside a full quarter
  EXPECT_TRUE(o.touched(6, 0, 0));
  EXPECT_FALSE(o.touched(5, 32, 32));
  for (int y = 32; y < 64; y += 4)
    for (int x = 32; x < 64; x += 4) {
      EXPECT_FALSE(o.full(6, 0, 0));
      // Pixels two at a time: a block is full when its 16 pixels are.
      for (int p = 0; p < 16; p += 2) o.addPixels(x, y, 3u << p);
      EXPECT_TRUE(o.full(2, x, y));
    }
  EXPECT_TRUE(o.full(5, 32, 32));
  EXPECT_TRUE(o.full(6, 0, 0));
}

TEST(Occupancy, RectanglesAreFullOnlyWhereEveryWindowUnderThemIs) {
  Occupancy o;
  o.clear(1);
  o.markFull(4, 16, 16);  // pixels 16…31 × 16…31
  o.markFull(3, 32, 16);  // 32…39 × 16…23
  EXPECT_TRUE(o.rectFull(16, 16, 31, 31));
  EXPECT_TRUE(o.rectFull(20, 17, 39, 23));
  EXPECT_FALSE(o.rectFull(20, 17, 40, 23));
  EXPECT_FALSE(o.rectFull(20, 17, 39, 24));
  EXPECT_FALSE(o.rectFull(0, 0, 63, 63));
  o.addPixels(40, 16, 0xFFFF);
  EXPECT_TRUE(o.rectFull(20, 17, 43, 19));
}

TEST(Occupancy, APixelIsOccupiedWhenAllItsSamplesAre) {
  Occupancy o;
  o.clear(16);
  uint32_t masks[2][16] = {};
  masks[0][5] = 0x00FF;
  o.addSamples(8, 4, masks);
  EXPECT_EQ(o.pixels(8, 4), 0u);
  masks[0][5] = 0xFF00;
  masks[0][6] = 0xFFFF;
  o.addSamples(8, 4, masks);
  EXPECT_EQ(o.pixels(8, 4), (1u << 5) | (1u << 6));
  const uint32_t(*held)[16] = o.samples(8, 4);
  ASSERT_NE(held, nullptr);
  EXPECT_EQ(held[0][5], 0xFFFFu);
  EXPECT_EQ(held[0][4], 0u);
  EXPECT_EQ(o.samples(0, 0), nullptr);  // an untouched block holds nothing
  o.clear(16);
  EXPECT_EQ(o.pixels(8, 4), 0u);
}

// Hybrid masking's depth bounds: exact from the depth buffer when a block becomes full, the
// largest of the children's for a parent, lowered (never raised) when drawn over again; a
// rectangle is hidden for a triangle whose smallest depth there is not below its windows' bounds.
TEST(Occupancy, DepthBoundsComeFromTheDepthBufferAndPropagate) {
  Occupancy o;
  o.clear(1);
  EXPECT_EQ(o.zmaxOver(2, 0, 0), Occupancy::kNoBound);
  float depth[16];
  for (int i = 0; i < 16; ++i) depth[i] = 0.1f + 0.01f * float(i);
  o.addPixels(0, 0, 0x00FF, depth);
  EXPECT_EQ(o.zmaxOver(2, 0, 0), Occupancy::kNoBound);  // not full yet
  o.addPixels(0, 0, 0xFF00, depth);
  EXPECT_FLOAT_EQ(o.zmaxOver(2, 0, 0), 0.25f);
  // The other three blocks of the 8×8 window, by whole-window fills with their own bounds.
  o.markFull(2, 4, 0, 0.5f);
  o.markFull(2, 0, 4, 0.3f);
  EXPECT_EQ(o.zmaxOver(3, 0, 0), Occupancy::kNoBound);
  o.markFull(2, 4, 4, 0.2f);
  EXPECT_FLOAT_EQ(o.zmaxOver(3, 0, 0), 0.5f);
  o.lowerZmax(2, 4, 0, 0.7f);  // not lower: kept
  EXPECT_FLOAT_EQ(o.zmaxOver(2, 4, 0), 0.5f);
  o.lowerZmax(2, 4, 0, 0.4f);
  EXPECT_FLOAT_EQ(o.zmaxOver(3, 0, 0), 0.4f);
  EXPECT_TRUE(o.rectHidden(1, 1, 6, 6, 0.4f));
  EXPECT_FALSE(o.rectHidden(1, 1, 6, 6, 0.39f));
  EXPECT_TRUE(o.rectHidden(0, 0, 3, 3, 0.3f));   // the first block alone: bound 0.25
  EXPECT_FALSE(o.rectHidden(0, 0, 8, 3, 0.9f));  // reaches an empty block
}

// Random triangles of every size at distinct constant depths, sorted nearest first: a valid
// priority order without interpenetration.
DrawPackets frontToBackScene(int w, int h, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  struct Tri {
    double x[3], y[3];
    float z, r, g, b;
  };
  std::vector<Tri> tris;
  for (int i = 0; i < count; ++i) {
    Tri t;
    const double size = std::exp2(u(rng) * 8);  // 1 … 256 px
    const double cx = u(rng) * w, cy = u(rng) * h;
    for (int k = 0; k < 3; ++k) {
      t.x[k] = cx + (u(rng) - 0.5) * size;
      t.y[k] = cy + (u(rng) - 0.5) * size;
    }
    t.z = float(0.05 + 0.9 * (i + u(rng) * 0.5) / count);
    t.r = float(u(rng));
    t.g = float(u(rng));
    t.b = float(u(rng));
    tris.push_back(t);
  }
  std::shuffle(tris.begin(), tris.end(), rng);
  std::stable_sort(tris.begin(), tris.end(), [](const Tri& a, const Tri& b) { return a.z < b.z; });
  DrawPackets p;
  for (const Tri& t : tris) {
    geometry::ClipVertex v[3];
    for (int k = 0; k < 3; ++k)
      v[k] = test::pixelVertex(t.x[k], t.y[k], w, h, t.z, 1, t.r, t.g, t.b);
    test::addTriangle(p, v[0], v[1], v[2]);
  }
  return p;
}

FrameSettings settings(int w, int h, int samples, raster::Masking masking) {
  FrameSettings s;
  s.width = w;
  s.height = h;
  s.samples = samples;
  s.clearColor[0] = 0.1f;
  s.clearColor[2] = 0.3f;
  s.masking = masking;
  return s;
}

TEST(PriorityMasking, EqualsTheZBufferOnFrontToBackSceneAtEverySampleCount) {
  for (int samples : {1, 4, 16, 64})
    for (unsigned seed : {1u, 2u}) {
      const int w = 190, h = 140;
      const DrawPackets p = frontToBackScene(w, h, 900, seed);
      FrameStats zStats, pStats;
      const test::Frame z =
          test::renderQuadtree(p, settings(w, h, samples, raster::Masking::none), 2, &zStats);
      const test::Frame m =
          test::renderQuadtree(p, settings(w, h, samples, raster::Masking::priority), 2, &pStats);
      EXPECT_TRUE(z == m) << samples << " samples, seed " << seed;
      // Masking did its work: windows and whole triangles dropped, fewer fragments shaded.
      EXPECT_GT(pStats.occludedWindows, 0u);
      EXPECT_GT(pStats.occludedTriangles, 0u);
      EXPECT_LT(pStats.fragments, zStats.fragments) << samples;
    }
}

TEST(PriorityMasking, SameFrameForAnyThreadCountAndBatching) {
  const int w = 200, h = 150;
  const DrawPackets p = frontToBackScene(w, h, 700, 3);
  for (int samples : {1, 16}) {
    const test::Frame ref =
        test::renderQuadtree(p, settings(w, h, samples, raster::Masking::priority), 1);
    EXPECT_TRUE(test::renderQuadtree(p, settings(w, h, samples, raster::Masking::priority), 2) ==
                ref);
    EXPECT_TRUE(test::renderQuadtree(p, settings(w, h, samples, raster::Masking::priority), 8) ==
                ref);
    FrameSettings batched = settings(w, h, samples, raster::Masking::priority);
    batched.batchTriangles = 97;  // occupancy kept per tile between batches
    EXPECT_TRUE(test::renderQuadtree(p, batched, 2) == ref) << samples;
    EXPECT_TRUE(test::renderQuadtree(p, settings(w, h, samples, raster::Masking::none), 2) == ref)
        << samples;
  }
}

// Colour sums (raster/framebuffer.h): under anti-aliased priority masking every sample is written
// once, so the tiles keep per pixel the sum of its samples instead of N planes — the same image bit
// for bit, at every sample count, thread count and batching; and not used where a sample may be
// written twice (the Z-buffer, hybrid masking).
TEST(PriorityMasking, ColourSumsResolveToTheSamePixels) {
  const int w = 190, h = 140;
  const DrawPackets p = frontToBackScene(w, h, 900, 7);
  for (int samples : {4, 16, 64}) {
    FrameSettings planes = settings(w, h, samples, raster::Masking::priority), sums = planes;
    sums.colorSums = true;
    bool used = false;
    const std::vector<uint16_t> ref = test::renderResolved(p, planes, 2, &used);
    EXPECT_FALSE(used);
    EXPECT_TRUE(test::renderResolved(p, sums, 2, &used) == ref) << samples;
    EXPECT_TRUE(used);
    EXPECT_TRUE(test::renderResolved(p, sums, 1) == ref) << samples;
    EXPECT_TRUE(test::renderResolved(p, sums, 8) == ref) << samples;
    sums.batchTriangles = 97;  // the whole-frame buffer's sums, kept between batches
    EXPECT_TRUE(test::renderResolved(p, sums, 2, &used) == ref) << samples;
    EXPECT_TRUE(used);
    // The Z-buffer's pixels are the same (a valid order); it and hybrid masking keep planes.
    for (const raster::Masking m : {raster::Masking::none, raster::Masking::hybrid}) {
      FrameSettings other = settings(w, h, samples, m);
      other.colorSums = true;
      EXPECT_TRUE(test::renderResolved(p, other, 2, &used) == ref) << samples;
      EXPECT_FALSE(used);
    }
  }
}

// Without a valid order masking is not the Z-buffer: a far triangle given first hides a near one
// (the documented price of priority masking; hybrid masking keeps the depth test for this).
TEST(PriorityMasking, TrustsTheOrderItIsGiven) {
  const int w = 64, h = 64;
  DrawPackets p;
  auto square = [&](float z, float r) {
    test::addTriangle(p, test::pixelVertex(8, 8, w, h, z, 1, r, 0, 0),
                      test::pixelVertex(56, 8, w, h, z, 1, r, 0, 0),
                      test::pixelVertex(56, 56, w, h, z, 1, r, 0, 0));
  };
  square(0.8f, 1.0f);  // far, first
  square(0.2f, 0.5f);  // near, second
  const test::Frame z = test::renderQuadtree(p, settings(w, h, 1, raster::Masking::none));
  const test::Frame m = test::renderQuadtree(p, settings(w, h, 1, raster::Masking::priority));
  EXPECT_EQ(z.channel(50, 20, 0), 32768);  // the near one (0.5)
  EXPECT_EQ(m.channel(50, 20, 0), 65535);  // the first one
}

// Hybrid masking keeps the depth test and drops only what depth bounds prove hidden: on scenes in
// any order — interpenetrating triangles of every size, vertices behind the eye and beyond the
// far plane — the Z-buffer's frame sample for sample, at every sample count.
TEST(HybridMasking, EqualsTheZBufferInAnyOrder) {
  for (int samples : {1, 4, 16, 64})
    for (unsigned seed : {4u, 5u}) {
      const int w = 170, h = 120;
      const DrawPackets p = test::randomScene(w, h, 500, seed, seed == 5);
      const test::Frame z =
          test::renderQuadtree(p, settings(w, h, samples, raster::Masking::none), 2);
      FrameStats stats;
      const test::Frame m =
          test::renderQuadtree(p, settings(w, h, samples, raster::Masking::hybrid), 2, &stats);
      EXPECT_TRUE(z == m) << samples << " samples, seed " << seed;
      // Tiles woke part-way, their occupancy rebuilt from the depth buffer (drawLists).
      EXPECT_GT(stats.hybridWoken, 0u);
    }
}

// … and on front-to-back input it drops hidden work like priority masking, in every order the
// same frame; for any thread count and batching. Where nothing arrives behind what is drawn
// (back to front) it never wakes.
TEST(HybridMasking, DropsHiddenWorkInEveryOrderWithTheSameFrame) {
  const int w = 190, h = 140;
  DrawPackets f2b = frontToBackScene(w, h, 900, 6), b2f = f2b;
  // The same triangles back to front.
  for (size_t t = 0; t < b2f.indices.size() / 3; ++t)
    for (int k = 0; k < 3; ++k)
      b2f.indices[t * 3 + size_t(k)] =
          f2b.indices[(f2b.indices.size() / 3 - 1 - t) * 3 + size_t(k)];
  for (int samples : {1, 16}) {
    FrameStats zs, fs, bs;
    const test::Frame z =
        test::renderQuadtree(f2b, settings(w, h, samples, raster::Masking::none), 2, &zs);
    const test::Frame f =
        test::renderQuadtree(f2b, settings(w, h, samples, raster::Masking::hybrid), 2, &fs);
    const test::Frame b =
        test::renderQuadtree(b2f, settings(w, h, samples, raster::Masking::hybrid), 2, &bs);
    EXPECT_TRUE(f == z) << samples;
    EXPECT_TRUE(b == test::renderQuadtree(b2f, settings(w, h, samples, raster::Masking::none), 2));
    EXPECT_GT(fs.occludedTriangles, 0u);
    EXPECT_LT(fs.fragments, zs.fragments);
    EXPECT_GT(fs.hybridWoken, 0u);
    // Back to front nothing is ever hidden: the tiles stay the plain Z-buffer, with no masking
    // work to pay for.
    EXPECT_EQ(bs.hiddenFragments, 0u);
    EXPECT_EQ(bs.hybridWoken, 0u);
    EXPECT_EQ(bs.occludedWindows + bs.occludedTriangles, 0u);
    EXPECT_GT(zs.hiddenFragments, 0u);
    EXPECT_TRUE(test::renderQuadtree(f2b, settings(w, h, samples, raster::Masking::hybrid), 1) ==
                f);
    EXPECT_TRUE(test::renderQuadtree(f2b, settings(w, h, samples, raster::Masking::hybrid), 8) ==
                f);
    FrameSettings batched = settings(w, h, samples, raster::Masking::hybrid);
    batched.batchTriangles = 97;
    EXPECT_TRUE(test::renderQuadtree(f2b, batched, 2) == f) << samples;
  }
}

// A tile wakes only while a quarter of its triangles are still to come: rebuilding its occupancy
// from the whole depth buffer does not pay for the last few. One 64×64 tile: a near layer of
// `near` triangles, then `far` triangles wholly behind it (each hidden whole, 128 px, counts as
// 128 hidden pixels: 16 reach the wake work of 2048).
TEST(HybridMasking, WakesOnlyWithEnoughOfTheTileToCome) {
  auto scene = [](int near, int far) {
    DrawPackets p;
    auto strip = [&](int count, float z) {  // `count` triangles over the tile, in vertical strips
      const double width = 128.0 / count;   // of a strip: two triangles
      for (int i = 0; i < count; ++i) {
        const double x0 = (i / 2) * width, x1 = x0 + width;
        geometry::ClipVertex v[4] = {test::pixelVertex(x0, 0, 64, 64, z, 1, 1, 0, 0),
                                     test::pixelVertex(x1, 0, 64, 64, z, 1, 0, 1, 0),
                                     test::pixelVertex(x0, 64, 64, 64, z, 1, 0, 0, 1),
                                     test::pixelVertex(x1, 64, 64, 64, z, 1, 1, 1, 0)};
        if (i % 2 == 0)
          test::addTriangle(p, v[0], v[2], v[1]);
        else
          test::addTriangle(p, v[1], v[2], v[3]);
      }
    };
    strip(near, 0.2f);
    strip(far, 0.8f);
    return p;
  };
  for (int samples : {1, 16}) {
    // 32 far triangles of 128 px after 32 near ones: the 16th far one reaches the wake work with
    // half the tile's triangles still to come.
    FrameStats early;
    const DrawPackets a = scene(32, 32);
    const test::Frame wakes =
        test::renderQuadtree(a, settings(64, 64, samples, raster::Masking::hybrid), 1, &early);
    EXPECT_EQ(early.hybridWoken, 1u) << samples;
    EXPECT_GT(early.occludedTriangles + early.occludedWindows, 0u) << samples;
    EXPECT_TRUE(wakes ==
                test::renderQuadtree(a, settings(64, 64, samples, raster::Masking::none), 1));
    // The same 32 far triangles after 128 near ones (of 32 px): the wake work is reached with 17
    // of 160 triangles to come (the one just drawn counted) — the tile stays the Z-buffer.
    FrameStats late;
    const DrawPackets b = scene(128, 32);
    const test::Frame sleeps =
        test::renderQuadtree(b, settings(64, 64, samples, raster::Masking::hybrid), 1, &late);
    EXPECT_EQ(late.hybridWoken, 0u) << samples;
    EXPECT_GT(late.hiddenFragments, 2048u) << samples;
    EXPECT_TRUE(sleeps ==
                test::renderQuadtree(b, settings(64, 64, samples, raster::Masking::none), 1));
  }
}

// Objects of eight triangles each around a centre, nearest first (each triangle at its own depth,
// objects separated in depth), with their bounds
// (as the renderer gives each instance, geometry::boundObject): a large near object hides many.
DrawPackets objectScene(int w, int h, int objects, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  DrawPackets p;
  for (int o = 0; o < objects; ++o) {
    const double size = o < 3 ? 0.6 * w : std::exp2(3 + u(rng) * 4);  // three near walls
    const double cx = u(rng) * w, cy = u(rng) * h;
    const float z = float(0.05 + 0.9 * (o + 0.5) / objects);
    render::DrawCall call;
    call.firstTriangle = uint32_t(p.indices.size() / 3);
    Vec3 lo{1e9f, 1e9f, 1e9f}, hi = -lo;
    for (int t = 0; t < 8; ++t) {
      geometry::ClipVertex v[3];
      for (auto& vert : v) {
        vert = test::pixelVertex(cx + (u(rng) - 0.5) * size, cy + (u(rng) - 0.5) * size, w, h,
                                 z + float(t * 0.05 / objects), 1, float(u(rng)), float(u(rng)),
                                 float(u(rng)));
        lo = {std::min(lo.x, vert.x), std::min(lo.y, vert.y), std::min(lo.z, vert.z)};
        hi = {std::max(hi.x, vert.x), std::max(hi.y, vert.y), std::max(hi.z, vert.z)};
      }
      p.vertices.insert(p.vertices.end(), {v[0], v[1], v[2]});
      for (uint32_t k = 0; k < 3; ++k) p.indices.push_back(uint32_t(p.vertices.size()) - 3 + k);
    }
    call.triangleCount = 8;
    call.cull = geometry::CullMode::none;
    call.bounded = geometry::boundObject(Mat4{}, lo, hi, {w, h}, call.bound);
    p.calls.push_back(call);
  }
  return p;
}

// Object-space culling (SPEC §4, seed 004): objects whose bounds lie in occupied windows are
// dropped whole — in the tiles before their records are read, and, in frames of several batches,
// before setup — and the frame stays the Z-buffer's, for every thread count and batching.
TEST(ObjectCulling, DropsHiddenObjectsWholeWithTheZBufferFrame) {
  const int w = 230, h = 170;
  const DrawPackets p = objectScene(w, h, 400, 7);
  for (const raster::Masking masking : {raster::Masking::priority, raster::Masking::hybrid})
    for (int samples : {1, 16}) {
      const test::Frame z =
          test::renderQuadtree(p, settings(w, h, samples, raster::Masking::none), 2);
      FrameStats stats, batchedStats;
      EXPECT_TRUE(test::renderQuadtree(p, settings(w, h, samples, masking), 2, &stats) == z)
          << samples;
      EXPECT_GT(stats.occludedObjects, 0u);
      EXPECT_EQ(stats.culledOccluded, 0u);  // one batch: all set up before any tile
      EXPECT_TRUE(test::renderQuadtree(p, settings(w, h, samples, masking), 1) == z);
      EXPECT_TRUE(test::renderQuadtree(p, settings(w, h, samples, masking), 8) == z);
      FrameSettings batched = settings(w, h, samples, masking);
      batched.batchTriangles = 200;
      EXPECT_TRUE(test::renderQuadtree(p, batched, 2, &batchedStats) == z) << samples;
      EXPECT_GT(batchedStats.culledOccluded, 0u);
      EXPECT_LT(batchedStats.drawn, stats.drawn);
      // Without bounds nothing is dropped whole, and the frame is the same.
      DrawPackets unbounded = p;
      for (render::DrawCall& c : unbounded.calls) c.bounded = false;
      FrameStats plain;
      EXPECT_TRUE(test::renderQuadtree(unbounded, batched, 2, &plain) == z);
      EXPECT_EQ(plain.occludedObjects + plain.culledOccluded, 0u);
    }
}

}  // namespace
}  // namespace sv
