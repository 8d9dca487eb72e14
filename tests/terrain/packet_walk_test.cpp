// The packet walk (terrain/packet_walk.h) against the per-ray exact solve and the dense march:
// blocks of rays over a fractal table, bilinear and bicubic, grazing ones and blocks whose rays
// part included; every SIMD target and the scalar fallback bit for bit; walks cut short and
// resumed.
#include "terrain/packet_walk.h"

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "formats/heights.h"
#include "terrain/caster.h"
#include "terrain/dense_march.h"

namespace sv::terrain {
namespace {

using tests::denseMarch;

constexpr double kSpacing = 20;  // metres between samples

// A block's rays: one origin, 16 directions around a centre one, `spread` radians apart (a 4×4
// block of pixels at ~0.5 mrad a pixel; blocks whose rays part over ridges need no more).
struct Block {
  Caster::Packet packet;
  double pitch = 0;
};

Block randomBlock(std::mt19937& rng, double spread, double s1) {
  std::uniform_real_distribution<double> u(0, 1);
  const double half = 64 * kSpacing * 1.2;
  Block b;
  Caster::Packet& p = b.packet;
  p.origin = {(2 * u(rng) - 1) * half, 5 + 700 * u(rng), (2 * u(rng) - 1) * half};
  const double yaw = 2 * M_PI * u(rng);
  b.pitch = -(0.2 + 40 * u(rng) * u(rng)) * M_PI / 180;
  p.count = kPacketRays;
  for (int l = 0; l < kPacketRays; ++l) {
    const double dy = ((l & 3) - 1.5) * spread, dp = ((l >> 2) - 1.5) * spread;
    const double pitch = b.pitch + dp, heading = yaw + dy;
    p.dir[l] = {std::cos(pitch) * std::cos(heading), std::sin(pitch),
                std::cos(pitch) * std::sin(heading)};
    p.s0[l] = 0;
    p.s1[l] = s1;
  }
  return b;
}

// A fractal table, bilinear or on its Catmull–Rom surface.
struct Ground {
  explicit Ground(Interpolation i = Interpolation::bilinear) : interp(i) {}
  Interpolation interp;
  HeightField field = formats::generateFractal(129, kSpacing, 600, 9).value();
  Pyramid pyramid{field, interp};
  Caster caster{field, pyramid, interp, Placement{}};
  mutable CastCounters counters;
};

// Blocks walked over the table whole: every lane meets the surface where the dense march does.
void expectLanesMeetTheDenseMarch(const Ground& g) {
  std::mt19937 rng(3);
  int hits = 0, misses = 0, grazing = 0;
  for (int k = 0; k < 60; ++k) {
    Block b = randomBlock(rng, k % 2 ? 5e-4 : 2e-2, 4000);  // a block's, or rays that part
    if (std::fabs(b.pitch) < 2 * M_PI / 180) ++grazing;
    g.caster.walkPacket(b.packet, g.pyramid.gridLevel(), 1 << 20, g.counters);
    for (int l = 0; l < kPacketRays; ++l) {
      const Vec3d d = b.packet.dir[l];
      const double want = denseMarch(g.caster, b.packet.origin, d, 0, 4000);
      const double got = b.packet.hit[l];
      ASSERT_EQ(std::isnan(got), std::isnan(want))
          << "block " << k << " lane " << l << " got " << got << " want " << want;
      if (std::isnan(got)) {
        ++misses;
        EXPECT_EQ(b.packet.reached[l], 4000.0);  // the whole span walked
        continue;
      }
      ++hits;
      // 2·10⁻³ of a grid step along the ray, as the per-ray cast (caster_test.cpp).
      ASSERT_NEAR(got, want, 2e-3 * kSpacing) << "block " << k << " lane " << l;
    }
  }
  EXPECT_GT(hits, 400);
  EXPECT_GT(misses, 20);
  EXPECT_GT(grazing, 3);
}

TEST(PacketWalk, EveryLaneMeetsTheSurfaceWhereTheDenseMarchDoes) {
  expectLanesMeetTheDenseMarch(Ground{});
}

TEST(PacketWalk, OnTheBicubicTableEveryLaneMeetsThePatchWhereTheDenseMarchDoes) {
  // Lanes walk the cells by their patches' Bézier tops, are parked at those they may touch, and
  // solve those patches together (SolvePatches): the same hits as the dense march of the surface.
  expectLanesMeetTheDenseMarch(Ground{Interpolation::bicubic});
}

// Two steps at a time, each lane resumed from `reached`, meets what one whole walk meets.
void expectACutWalkResumes(const Ground& g) {
  std::mt19937 rng(5);
  const int n = g.pyramid.gridLevel();
  int resumed = 0;
  for (int k = 0; k < 40; ++k) {
    Block whole = randomBlock(rng, 1e-3, 4000);
    Caster::Packet cut = whole.packet;
    g.caster.walkPacket(whole.packet, n, 1 << 20, g.counters);
    double hit[kPacketRays];
    for (int l = 0; l < kPacketRays; ++l) hit[l] = NAN;
    for (int round = 0; round < 2000; ++round) {
      g.caster.walkPacket(cut, n, 2, g.counters);
      bool more = false;
      for (int l = 0; l < kPacketRays; ++l) {
        if (!std::isnan(cut.hit[l])) hit[l] = cut.hit[l];
        const bool open = std::isnan(cut.hit[l]) && cut.reached[l] < cut.s1[l];
        cut.s0[l] = open ? cut.reached[l] : cut.s1[l] + 1;  // done lanes idle
        more |= open;
      }
      if (!more) break;
      ++resumed;
    }
    for (int l = 0; l < kPacketRays; ++l) {
      ASSERT_EQ(std::isnan(hit[l]), std::isnan(whole.packet.hit[l])) << k << " lane " << l;
      if (!std::isnan(hit[l])) {
        EXPECT_NEAR(hit[l], whole.packet.hit[l], 1e-4 * kSpacing);
      }
    }
  }
  EXPECT_GT(resumed, 40);
}

TEST(PacketWalk, AWalkCutShortResumesWhereItStopped) { expectACutWalkResumes(Ground{}); }

TEST(PacketWalk, OnTheBicubicTableAWalkCutShortResumesWhereItStopped) {
  // Lanes parked at a patch when their steps run out are solved before the walk returns.
  expectACutWalkResumes(Ground{Interpolation::bicubic});
}

TEST(PacketWalk, AgreesWithThePerRaySolveOnAMeanLevel) {
  // A coarser level of the mean pyramid (the levels of detail): the packet and Caster::cast at
  // the same level of detail (a pixel so wide that every s asks for it) meet the same surface.
  const Ground g;
  std::mt19937 rng(9);
  const int level = g.pyramid.gridLevel() - 2;
  int hits = 0;
  for (int k = 0; k < 30; ++k) {
    Block b = randomBlock(rng, 1e-3, 4000);
    g.caster.walkPacket(b.packet, level, 1 << 20, g.counters);
    for (int l = 0; l < kPacketRays; ++l) {
      // cast() at `level` everywhere: lodLevel(s, pixel, stretch) = level for pixel·s·stretch in
      // (2, 4] — not constant in s, so the single-level reference is the dense march of the
      // level's surface itself.
      const Vec3d o = b.packet.origin, d = b.packet.dir[l];
      const double speed = std::hypot(d.x, d.z) / kSpacing;
      double want = NAN;
      for (double s = 0; s <= 4000; s += 1.0 / 256 / speed) {
        const Caster::MapPoint m = g.caster.toMap(o + d * s);
        const double h = g.caster.surface(m.gx, m.gy, level);
        if (!std::isnan(h) && m.h - h <= 0) {
          want = s;
          break;
        }
      }
      ASSERT_EQ(std::isnan(b.packet.hit[l]), std::isnan(want)) << k << " lane " << l;
      if (std::isnan(want)) continue;
      ++hits;
      EXPECT_NEAR(b.packet.hit[l], want, 1.0 / 256 / speed + 1e-3 * kSpacing);
    }
  }
  EXPECT_GT(hits, 200);
}

TEST(PacketWalk, WalksEachLevelOfDetailWhereItHolds) {
  // walkPacketLevels: a ray (a packet of one, its own stretch) against the dense march of the
  // surface its level of detail gives at each s — the levels coarsening with distance.
  const Ground g;
  std::mt19937 rng(17);
  const double pixel = 1e-2;  // grid steps per unit s: levels n … n − 5 over the rays' 4000 m
  int hits = 0, coarse = 0;
  for (int k = 0; k < 20; ++k) {
    const Block b = randomBlock(rng, 2e-2, 4000);
    for (int l = 0; l < kPacketRays; ++l) {
      Caster::Packet p = b.packet;
      p.count = 1;
      p.dir[0] = b.packet.dir[l];
      const Vec3d o = p.origin, d = p.dir[0];
      const double stretch = g.caster.stretch(d);
      g.caster.walkPacketLevels(p, pixel, stretch, 1 << 20, g.counters);
      const double step = 1.0 / 256 / (std::hypot(d.x, d.z) / kSpacing);
      double want = NAN;
      for (double s = 0; s <= 4000; s += step) {
        const Caster::MapPoint m = g.caster.toMap(o + d * s);
        const double h = g.caster.surface(m.gx, m.gy, g.caster.lodLevel(s, pixel, stretch));
        if (!std::isnan(h) && m.h - h <= 0) {
          want = s;
          break;
        }
      }
      ASSERT_EQ(std::isnan(p.hit[0]), std::isnan(want)) << k << " lane " << l;
      if (std::isnan(want)) continue;
      ++hits;
      coarse += g.caster.lodLevel(want, pixel, stretch) < g.pyramid.gridLevel();
      EXPECT_NEAR(p.hit[0], want, step + 1e-3 * kSpacing) << k << " lane " << l;
    }
  }
  EXPECT_GT(hits, 100);
  EXPECT_GT(coarse, 30);
}

void expectEveryTargetGivesTheSameBits(const Ground& g) {
  std::vector<double> first;
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    std::mt19937 rng(11);
    std::vector<double> got;
    for (int k = 0; k < 40; ++k) {
      Block b = randomBlock(rng, k % 2 ? 5e-4 : 2e-2, 4000);
      b.packet.count = 1 + k % kPacketRays;  // part-filled packets too
      g.caster.walkPacket(b.packet, g.pyramid.gridLevel(), 6, g.counters);
      for (int l = 0; l < b.packet.count; ++l)
        got.insert(got.end(), {b.packet.hit[l], b.packet.reached[l]});
    }
    if (first.empty()) {
      first = got;
      continue;
    }
    ASSERT_EQ(got.size(), first.size());
    EXPECT_EQ(std::memcmp(got.data(), first.data(), got.size() * sizeof(double)), 0)
        << hwy::TargetName(target);
  }
  hwy::SetSupportedTargetsForTest(0);
}

TEST(PacketWalk, EveryTargetGivesTheSameBits) {
  expectEveryTargetGivesTheSameBits(Ground{});
  expectEveryTargetGivesTheSameBits(Ground{Interpolation::bicubic});
}

// A flat table with one spike: rays that pass just below its top meet it, rays just above it
// meet nothing — whatever square of the skip map the spike is in, on its edges and corners too.
// A walk that passed a square it should have entered (its top misread, the ray's lowest point in
// the square misjudged by a third of a code, the wrong square) misses the spike.
TEST(PacketWalk, ASquareIsPassedOnlyWhereTheRayStaysAboveItsTop) {
  HeightField field;
  field.width = field.height = 65;
  field.spacingU = field.spacingV = 10;
  field.originV = 640;
  field.scale = 0.01;  // a code a centimetre
  const uint16_t ground = 1000, spike = 20000;
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(0, 1);
  int rays = 0;
  for (const auto& [si, sj] : {std::pair{37, 29}, {40, 28}, {44, 44}, {41, 30}, {12, 52}}) {
    field.q.assign(size_t(field.width) * size_t(field.height), ground);
    field.q[size_t(sj) * size_t(field.width) + size_t(si)] = spike;
    const Pyramid pyramid(field, Interpolation::bilinear);
    const Caster caster(field, pyramid, Interpolation::bilinear, Placement{});
    CastCounters counters;
    for (const double margin : {-0.3, 0.3}) {  // codes below and above the top
      const Vec3d target = caster.toWorld(si, sj, (spike + margin) * field.scale);
      for (int k = 0; k < kPacketRays; ++k) {
        // Level to 30° down (above the top: level), any heading, from 200 to 400 m away, through
        // the point beside the spike's top: a ray a packet (a packet has one origin).
        const double pitch = margin > 0 || k % 4 == 0 ? 0 : -30 * u(rng) * M_PI / 180;
        const double heading = 2 * M_PI * u(rng), distance = 200 + 200 * u(rng);
        Caster::Packet p;
        p.count = 1;
        p.dir[0] = {std::cos(pitch) * std::cos(heading), std::sin(pitch),
                    std::cos(pitch) * std::sin(heading)};
        p.origin = target - p.dir[0] * distance;
        p.s0[0] = 0, p.s1[0] = 2 * distance;
        caster.walkPacket(p, pyramid.gridLevel(), 1 << 20, counters);
        ++rays;
        if (margin < 0) {
          ASSERT_FALSE(std::isnan(p.hit[0])) << si << "," << sj << " ray " << k;
          EXPECT_LE(p.hit[0], distance + 1e-3);
        } else {
          EXPECT_TRUE(std::isnan(p.hit[0])) << si << "," << sj << " ray " << k;
        }
      }
    }
  }
  EXPECT_EQ(rays, 5 * 2 * kPacketRays);
}

TEST(PacketWalk, RaysOffTheTableAndEmptySpansAreIdle) {
  const Ground g;
  Caster::Packet p;
  p.origin = {1e6, 100, 1e6};  // far beyond the table, looking away from it
  p.count = 3;
  for (int l = 0; l < 3; ++l) p.dir[l] = {1, -0.1, 0}, p.s0[l] = 0, p.s1[l] = 1000;
  p.s0[2] = 2000;  // an empty span
  g.caster.walkPacket(p, g.pyramid.gridLevel(), 8, g.counters);
  for (int l = 0; l < 3; ++l) {
    EXPECT_TRUE(std::isnan(p.hit[l]));
    EXPECT_EQ(p.reached[l], p.s1[l]);
  }
}

}  // namespace
}  // namespace sv::terrain
