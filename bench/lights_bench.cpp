// Kernel benchmarks of the light pass's per-light work (issue 60's cost model, docs/lights.md):
//   the preparation of BENCH.md's `lights` scene (100 000 lights at 1920×1080: projection, blink,
//   lobe, fog, energy, size, the weight sums and the binning to tiles, on one thread)
//                                                                          → ns a candidate light
//   the tiles' draw of its splats over a far depth (visibility and the block adds, one thread)
//                                                                          → ns a drawn light
//   one small splat (radius 1.25–1.5 px) added to a tile's colour at a random place
//                                                                          → ns a splat
// The target's budget a light — 40 ns of one core, all of it — is in docs/lights.md. Run:
// build/bench/sv_lights_bench (SV_BENCH_TARGET=avx2 for the AVX2 kernels on an AVX-512 machine).
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

#include "bench_target.h"
#include "core/thread_pool.h"
#include "lights/light_pass.h"
#include "lights/splat_blocks.h"
#include "raster/framebuffer.h"
#include "synthvis/generators.h"

namespace {

constexpr int kWidth = 1920, kHeight = 1080;

// BENCH.md's `lights` scene and a 1920×1080 frame of far depth, black, one worker.
struct LightsFrame {
  sv::scene::Scene scene;
  sv::raster::FrameBuffer fb;
  sv::core::ThreadPool pool{1};
  sv::lights::LightPass pass;

  LightsFrame() {
    sv::generators::LightsParams params;
    auto made = sv::generators::generateLights(params);
    if (!made.ok()) {
      std::fprintf(stderr, "sv_lights_bench: %s\n", made.error().str().c_str());
      std::exit(1);
    }
    scene = std::move(made.value());
    fb.resize(kWidth, kHeight);
    for (int t = 0; t < fb.tileCount(); ++t) {
      std::fill_n(fb.tileDepth(t), sv::raster::kTilePixels, 1.0f);
      std::fill_n(fb.tileColor(t), sv::raster::kTilePixels * 3, uint16_t(0));
    }
    const sv::scene::Camera& c = scene.cameras.front();
    sv::lights::LightInput in;
    in.appearances = scene.lightAppearances;
    in.points = scene.lightPoints;
    in.groups = scene.lightGroups;
    in.settings = scene.lightSettings;
    in.view = sv::Mat4::lookAt(c.position, c.target, c.up);
    in.projection = sv::Mat4::perspective(c.yfovDegrees * 3.14159265f / 180,
                                          float(kWidth) / float(kHeight), c.znear, c.zfar);
    in.fogBeta = scene.fog.enabled ? scene.fog.beta : 0.0f;
    pass.setLights(in);
  }
  void prepare() { pass.prepare(sv::raster::PassFrame{kWidth, kHeight, 1, nullptr, &pool}); }
  void drawTiles() {
    for (int t = 0; t < fb.tileCount(); ++t)
      pass.seeTile({t % fb.tilesX(), t / fb.tilesX(), fb.tileDepth(t), fb.tileColor(t), 0});
    for (int t = 0; t < fb.tileCount(); ++t)
      pass.drawTile({t % fb.tilesX(), t / fb.tilesX(), fb.tileDepth(t), fb.tileColor(t), 0});
  }
};

LightsFrame& frame() {
  static LightsFrame f;
  return f;
}

void BM_Prepare(benchmark::State& state) {
  LightsFrame& f = frame();
  for (auto _ : state) f.prepare();
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(f.scene.lightPoints.size()));
  state.counters["ns_a_light"] = benchmark::Counter(
      double(f.scene.lightPoints.size()),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_Prepare)->Unit(benchmark::kMillisecond);

void BM_DrawTiles(benchmark::State& state) {
  LightsFrame& f = frame();
  f.prepare();
  const std::vector<sv::lights::Splat> splats = f.pass.splats();
  const size_t drawn = splats.size();
  size_t large = 0, blocks = 0;
  for (const sv::lights::Splat& s : splats) {
    large += s.spanX > sv::lights::Splat::kKeptSpan || s.spanY > sv::lights::Splat::kKeptSpan;
    blocks += size_t(((s.firstX + s.spanX - 1) >> 2) - (s.firstX >> 2) + 1) *
              size_t(((s.firstY + s.spanY - 1) >> 2) - (s.firstY >> 2) + 1);
  }
  // What the draw does a light: the share of splats wider than four pixels (their weights worked
  // out again in every tile they reach) and the 4×4 blocks a splat touches on average.
  state.counters["large_share"] = double(large) / double(drawn);
  state.counters["blocks_a_splat"] = double(blocks) / double(drawn);
  for (auto _ : state) f.drawTiles();
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(drawn));
  state.counters["ns_a_light"] = benchmark::Counter(
      double(drawn), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_DrawTiles)->Unit(benchmark::kMillisecond);

void BM_AddSmallSplat(benchmark::State& state) {
  std::vector<uint16_t> tile(size_t(sv::raster::kTilePixels) * 3, 0);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> at(2, sv::raster::kTileSize - 2), size(1.25f, 1.5f);
  // 1 024 splats, their axis weights worked out as the pass keeps them.
  struct Kept {
    float kx[4], ky[4];
    sv::lights::SplatInTile part;
  };
  std::vector<Kept> splats(1024);
  for (Kept& k : splats) {
    const float x = at(rng), y = at(rng), r = size(rng);
    int fx, fy;
    const int nx = sv::lights::splatAxis4(x, r, k.kx, fx);
    const int ny = sv::lights::splatAxis4(y, r, k.ky, fy);
    k.part.kernelX = fx, k.part.kernelY = fy;
    k.part.x0 = fx, k.part.x1 = fx + nx - 1, k.part.y0 = fy, k.part.y1 = fy + ny - 1;
    k.part.rgb[0] = k.part.rgb[1] = k.part.rgb[2] = 100;
  }
  for (Kept& k : splats) k.part.kx = k.kx, k.part.ky = k.ky;
  size_t i = 0;
  for (auto _ : state) {
    sv::lights::addSplat(tile.data(), 1, splats[i++ & 1023].part);
    benchmark::DoNotOptimize(tile.data());
  }
  state.SetItemsProcessed(int64_t(state.iterations()));
}
BENCHMARK(BM_AddSmallSplat);

}  // namespace

int main(int argc, char** argv) { return sv::bench::runBenchmarks(argc, argv, "sv_lights_bench"); }
