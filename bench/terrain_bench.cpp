// Terrain kernels (Google Benchmark; docs/terrain.md, "Cost model"): the rays of BENCH.md's
// `terrain` view — a 1024² fractal table 40 km wide, 1200 m of relief, the eye 300 m above its
// centre looking north 8° down, 60° vertical field of view at 1920×1080 — in 4×4 blocks of
// pixels, each block starting a few cells before its nearest ray's hit (where the window march
// leaves a block: docs/terrain.md, "Casting"):
//   the per-ray cast from the block's start (Caster::cast: direct walk, march, exact solve) → rays/s
//   the packet walk of the same rays (Caster::walkPacket, 16 cells a lane)                → rays/s
//   the same rays walked from the eye at the levels of detail (walkPacketLevels)        → rays/s
// `finished` reports the share of rays the packet walk ended (a hit, or nothing before its limit).
// SV_BENCH_TARGET=avx2 (or avx3, sse4, scalar) runs the kernels on that SIMD target alone, to
// quote an AVX2 figure from an AVX-512 machine.
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "bench_target.h"
#include "formats/heights.h"
#include "terrain/caster.h"

namespace sv::terrain {
namespace {

struct View {
  HeightField field;
  Pyramid pyramid;
  std::unique_ptr<Caster> caster;
  std::vector<Caster::Packet> blocks;
};

const View& view() {
  static const View* v = [] {
    auto* w = new View;
    constexpr int kSize = 1024;
    constexpr double kExtent = 40960;
    w->field = formats::generateFractal(kSize + 1, kExtent / kSize, 1200, 1).value();
    w->pyramid = Pyramid(w->field, Interpolation::bilinear);
    w->caster = std::make_unique<Caster>(
        w->field, w->pyramid, Interpolation::bilinear,
        Placement{w->field.originU + kExtent / 2, w->field.originV - kExtent / 2, 0});
    const Caster& c = *w->caster;
    const double ground = c.surface(kSize / 2.0, kSize / 2.0);
    const Vec3d eye{0, ground + 300, 0};
    // Camera looking north (−z) 8° down; pixel (x, y) of 1920×1080 at depth 1.
    const double pitch = -8 * M_PI / 180, tanHalf = std::tan(30 * M_PI / 180);
    const Vec3d forward{0, std::sin(pitch), -std::cos(pitch)}, right{1, 0, 0};
    const Vec3d up = cross(right, forward);
    auto direction = [&](double px, double py) {
      const double sx = (2 * px / 1920 - 1) * tanHalf * 1920 / 1080;
      const double sy = (1 - 2 * py / 1080) * tanHalf;
      return forward + right * sx + up * sy;
    };
    std::mt19937 rng(1);
    std::uniform_int_distribution<int> bx(0, 1920 / 4 - 1), by(0, 1080 / 4 - 1);
    CastCounters counters;
    while (w->blocks.size() < 2000) {
      Caster::Packet p;
      p.origin = eye;
      p.count = kPacketRays;
      const int x0 = 4 * bx(rng), y0 = 4 * by(rng);
      double nearest = INFINITY, speed = 0;  // speed: cells per unit s
      for (int l = 0; l < kPacketRays; ++l) {
        p.dir[l] = direction(x0 + (l & 3) + 0.5, y0 + (l >> 2) + 0.5);
        const double hit = c.cast(eye, p.dir[l], 0, 1e6, counters);
        if (!std::isnan(hit)) nearest = std::min(nearest, hit);
        speed = std::max(speed, std::hypot(p.dir[l].x, p.dir[l].z) / c.field().spacingU);
      }
      if (!std::isfinite(nearest)) continue;  // sky
      // Four cells before the nearest hit: where a block's bundle march typically stops.
      const double start = std::max(0.0, nearest - 4 / speed);
      for (int l = 0; l < kPacketRays; ++l) p.s0[l] = start, p.s1[l] = 1e6;
      w->blocks.push_back(p);
    }
    return w;
  }();
  return *v;
}

void BM_TerrainRayCast(benchmark::State& state) {
  const View& v = view();
  CastCounters counters;
  size_t rays = 0;
  for (auto _ : state)
    for (const Caster::Packet& p : v.blocks)
      for (int l = 0; l < p.count; ++l) {
        benchmark::DoNotOptimize(v.caster->cast(p.origin, p.dir[l], p.s0[l], p.s1[l], counters));
        ++rays;
      }
  state.counters["rays/s"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
  state.counters["ns/ray"] =
      benchmark::Counter(double(rays), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_TerrainRayCast)->Unit(benchmark::kMillisecond);

// Walks every block of the view (a copy, prepared by `prepare`, walked by `walk`), and reports
// rays a second, ns a ray and the share of rays the walk finished.
template <class Prepare, class Walk>
void walkBlocks(benchmark::State& state, Prepare&& prepare, Walk&& walk) {
  const View& v = view();
  size_t rays = 0, finished = 0;
  for (auto _ : state)
    for (const Caster::Packet& block : v.blocks) {
      Caster::Packet p = block;
      prepare(p);
      walk(p);
      for (int l = 0; l < p.count; ++l)
        finished += !std::isnan(p.hit[l]) || p.reached[l] >= p.s1[l];
      rays += size_t(p.count);
    }
  state.counters["rays/s"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
  state.counters["ns/ray"] =
      benchmark::Counter(double(rays), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["finished"] = double(finished) / double(std::max<size_t>(rays, 1));
}

void BM_TerrainPacketWalk(benchmark::State& state) {
  const View& v = view();
  const int cells = int(state.range(0));
  CastCounters counters;
  walkBlocks(
      state, [](Caster::Packet&) {},
      [&](Caster::Packet& p) { v.caster->walkPacket(p, v.pyramid.gridLevel(), cells, counters); });
}
BENCHMARK(BM_TerrainPacketWalk)->Arg(8)->Arg(16)->Arg(64)->Unit(benchmark::kMillisecond);

// The same rays walked from the eye, at the levels of detail of BENCH.md's pixel
// (walkPacketLevels): the long walks the skip map's squares shorten.
void BM_TerrainPacketWalkFromTheEye(benchmark::State& state) {
  const View& v = view();
  // A pixel of 1920×1080 at 60° of vertical field, per unit s, in grid steps (40 m).
  const double pixel = 2 * std::tan(30 * M_PI / 180) / 1080 / v.field.spacingU;
  CastCounters counters;
  double stretch = 1;
  walkBlocks(
      state,
      [&](Caster::Packet& p) {
        stretch = 1;
        for (int l = 0; l < p.count; ++l) {
          p.s0[l] = 0;
          stretch = std::max(stretch, v.caster->stretch(p.dir[l]));
        }
      },
      [&](Caster::Packet& p) { v.caster->walkPacketLevels(p, pixel, stretch, 1024, counters); });
}
BENCHMARK(BM_TerrainPacketWalkFromTheEye)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace sv::terrain

int main(int argc, char** argv) { return sv::bench::runBenchmarks(argc, argv, "sv_terrain_bench"); }
