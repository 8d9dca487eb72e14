// Google Benchmark kernels (STYLE.md habit 13): seeded inputs, work-normalized rates.
//   setup per triangle            → triangles/s
//   one tile, small triangles      → triangles/s (coverage + depth + Gouraud), windows/s (coverage
//                                    tests: windows classified plus leaf pixel-centre tests)
//   one tile, large triangles      → pixels/s (fills)
//   setup, SIMD lanes              → triangles/s
//   edge-mask table look-up (AA)   → masks/s
//   whole frame, BENCH.md tris     → triangles/s
//   texture samples, per filter    → samples/s (scalar Texture::sample, SIMD sampleBlock)
//   resolve, a 1080p frame's tiles → pixels/s (16-bit linear tiles to the 8-bit sRGB image)
//   traversal, BENCH.md city       → instances/s (the tree culled to the view, levels chosen),
//                                    with and without the instance tree
// The tile and frame benchmarks take the samples per pixel as their last argument (1 = point
// sampling; 4, 16 = anti-aliasing with sub-pixel masks, issue 4).
#include <benchmark/benchmark.h>

#include <array>
#include <random>

#include "bench_scenes.h"
#include "core/check.h"
#include "output/resolve.h"
#include "raster/coverage_masks.h"
#include "raster/framebuffer.h"
#include "raster/rasterizer.h"
#include "render/camera.h"
#include "render/draw_packets.h"
#include "render/frame_renderer.h"
#include "synthvis/generators.h"
#include "texture/texture.h"

namespace sv {
namespace {

geometry::ClipVertex at(double x, double y, int w, int h, float z) {
  return {float(2 * x / w - 1), float(1 - 2 * y / h), 2 * z - 1, 1, 0.5f, 0.6f, 0.7f, 1};
}

// Triangles of about `area` px² inside a 64×64 tile at the origin of a 64×64 raster, set up for
// anti-aliasing (the pixel aperture) when `aperture`.
std::vector<geometry::TriangleSetup> tileTriangles(double area, int count, bool aperture) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<geometry::TriangleSetup> out;
  const double leg = std::sqrt(2 * area);
  while (int(out.size()) < count) {
    const double x = u(rng) * 64, y = u(rng) * 64, a = u(rng) * 6.283;
    geometry::TriangleSetup t;
    if (geometry::setupTriangle(
            at(x, y, 64, 64, float(u(rng))),
            at(x + leg * std::cos(a), y + leg * std::sin(a), 64, 64, 0.5f),
            at(x + leg * std::cos(a + 1.571), y + leg * std::sin(a + 1.571), 64, 64, 0.5f),
            {64, 64, aperture}, geometry::CullMode::none, t) == geometry::SetupOutcome::drawn)
      out.push_back(t);
  }
  return out;
}

void rasterTile(benchmark::State& state, double area) {
  const int count = int(state.range(0)), samples = int(state.range(1));
  const auto tris = tileTriangles(area, count, samples > 1);
  std::vector<uint32_t> list(tris.size());
  for (size_t i = 0; i < list.size(); ++i) list[i] = uint32_t(i);
  raster::FrameBuffer fb;
  fb.resize(64, 64, samples);
  const uint32_t* lists[1] = {list.data()};
  const uint32_t sizes[1] = {uint32_t(list.size())};
  raster::TileWork w;
  w.depth = fb.tileDepth(0);
  w.color = fb.tileColor(0);
  w.clear = true;
  w.setups = tris.data();
  w.lists = lists;
  w.listSizes = sizes;
  w.listCount = 1;
  w.coverage = samples > 1 ? raster::CoverageTables::forCount(samples) : nullptr;
  raster::RasterStats stats;
  for (auto _ : state) raster::rasterizeTile(w, stats);
  state.counters["triangles/s"] =
      benchmark::Counter(double(count) * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["pixels/s"] =
      benchmark::Counter(double(stats.fragments), benchmark::Counter::kIsRate);
  // Coverage tests: every window classified, every 4×4 leaf's 16 pixel-centre tests.
  uint64_t windows = 0;
  for (uint64_t n : stats.windows) windows += n;
  state.counters["windows/s"] = benchmark::Counter(double(windows), benchmark::Counter::kIsRate);
}

void BM_TileSmallTriangles(benchmark::State& s) { rasterTile(s, 10); }
void BM_TileMediumTriangles(benchmark::State& s) { rasterTile(s, 100); }
void BM_TileLargeTriangles(benchmark::State& s) { rasterTile(s, 1000); }
BENCHMARK(BM_TileSmallTriangles)->Args({1000, 1})->Args({1000, 4})->Args({1000, 16});
BENCHMARK(BM_TileMediumTriangles)->Args({200, 1})->Args({200, 4})->Args({200, 16});
BENCHMARK(BM_TileLargeTriangles)->Args({20, 1})->Args({20, 4})->Args({20, 16});

// 4096 small triangles of a 1080p raster, w between 1 and 2: the setup benchmarks' input.
std::vector<geometry::ClipVertex> setupInput() {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<geometry::ClipVertex> v(3 * 4096);
  for (size_t i = 0; i < v.size(); i += 3) {
    const double x = u(rng) * 1920, y = u(rng) * 1080;
    for (int k = 0; k < 3; ++k) {
      v[i + k] = at(x + u(rng) * 6, y + u(rng) * 6, 1920, 1080, float(u(rng)));
      v[i + k].w = float(1 + u(rng));
      v[i + k].x *= v[i + k].w;
      v[i + k].y *= v[i + k].w;
    }
  }
  return v;
}

void BM_SetupTriangle(benchmark::State& state) {
  const std::vector<geometry::ClipVertex> v = setupInput();
  geometry::TriangleSetup t;
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(geometry::setupTriangle(v[i], v[i + 1], v[i + 2], {1920, 1080},
                                                     geometry::CullMode::none, t));
    benchmark::DoNotOptimize(t);
    i = (i + 3) % v.size();
  }
  state.counters["triangles/s"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SetupTriangle);

// The same triangles through setupTriangles, several at a time in SIMD lanes.
void BM_SetupTrianglesBatched(benchmark::State& state) {
  const std::vector<geometry::ClipVertex> v = setupInput();
  std::vector<uint32_t> indices(v.size());
  for (size_t i = 0; i < indices.size(); ++i) indices[i] = uint32_t(i);
  std::vector<geometry::TriangleSetup> out(v.size() / 3);
  uint64_t outcomes[geometry::kSetupOutcomes] = {};
  for (auto _ : state) {
    benchmark::DoNotOptimize(geometry::setupTriangles(v.data(), indices.data(), out.size(),
                                                      {1920, 1080}, geometry::CullMode::none,
                                                      out.data(), outcomes));
  }
  state.counters["triangles/s"] =
      benchmark::Counter(double(out.size()) * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SetupTrianglesBatched);

// Anti-aliasing (issue 4): one edge's sub-pixel mask from the table, N samples.
void BM_EdgeMaskLookup(benchmark::State& state) {
  const raster::EdgeMaskTable table(*raster::samplePattern(int(state.range(0))));
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<std::array<double, 3>> edges(4096);
  for (auto& e : edges) e = {u(rng), u(rng), u(rng) * 0.7};
  size_t i = 0;
  uint64_t acc = 0;
  for (auto _ : state) {
    const auto& e = edges[i++ & 4095];
    acc ^= table.mask(e[0], e[1], e[2]);
  }
  benchmark::DoNotOptimize(acc);
  state.counters["masks/s"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_EdgeMaskLookup)->Arg(4)->Arg(16)->Arg(64);

// Texture sampling (issue 5): a range(2)-square texture, points scattered over it at levels of
// detail 0…4, by filter (0 nearest, 1 three-point, 2 bilinear, 3 trilinear three-point, 4
// trilinear); range(1) = 0 for the scalar Texture::sample, 1 for the SIMD sampleBlock (16 points a
// call). A 64² texture stays in the core's caches (the sampler's own cost); 1024² does not (texel
// memory latency, as in BENCH.md's textured scenes).
void BM_TextureSample(benchmark::State& state) {
  const auto filter = texture::Filter(state.range(0));
  const bool simd = state.range(1) != 0;
  const int side = int(state.range(2));
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> u(0, 1);
  texture::Level base;
  base.width = base.height = side;
  base.texels.resize(size_t(side) * size_t(side));
  for (auto& t : base.texels) t = {uint16_t(rng()), uint16_t(rng()), uint16_t(rng()), 65535};
  const texture::Texture tex(std::move(base), texture::Wrap::repeat, texture::Wrap::repeat);
  constexpr int kPoints = 4096;
  std::vector<float> lod(kPoints), x(kPoints), y(kPoints);
  for (int i = 0; i < kPoints; ++i) {
    lod[size_t(i)] = u(rng) * 4;
    x[size_t(i)] = u(rng) * float(side);
    y[size_t(i)] = u(rng) * float(side);
  }
  float sink = 0;
  for (auto _ : state) {
    for (int i = 0; i < kPoints; i += 16) {
      if (simd) {
        float out[4][16];
        texture::sampleBlock(tex, filter, &lod[size_t(i)], &x[size_t(i)], &y[size_t(i)], 16, out);
        sink += out[0][0];
      } else {
        for (int j = i; j < i + 16; ++j)
          sink += tex.sample(filter, lod[size_t(j)], x[size_t(j)], y[size_t(j)]).r;
      }
    }
  }
  benchmark::DoNotOptimize(sink);
  state.counters["samples/s"] =
      benchmark::Counter(double(kPoints) * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_TextureSample)->ArgsProduct({{0, 1, 2, 3, 4}, {0, 1}, {64, 1024}});

// BENCH.md tris through setup, binning and tiles (no vertex stage, no resolve), 1 thread, with
// the given samples per pixel.
void BM_FrameTris(benchmark::State& state) {
  const render::DrawPackets packets =
      bench::trisPackets(int(state.range(0)), double(state.range(1)));
  render::FrameRenderer fr(1);
  render::FrameSettings fs;
  fs.width = 1920;
  fs.height = 1080;
  fs.samples = int(state.range(2));
  for (auto _ : state) {
    FrameStats stats;
    SV_CHECK(fr.render(packets, fs, stats).ok());
  }
  state.counters["triangles/s"] = benchmark::Counter(
      double(packets.indices.size() / 3) * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_FrameTris)
    ->Args({100000, 10, 1})
    ->Args({10000, 1000, 1})
    ->Args({100000, 10, 4})
    ->Args({10000, 1000, 4})
    ->Unit(benchmark::kMillisecond);

// The resolve of every tile of a 1920×1080 frame into its image, from tiles of smooth colours
// with some noise, as rendered frames have (each tile its own buffer, as the frame buffer holds
// them).
void BM_ResolveFrame(benchmark::State& state) {
  constexpr int kW = 1920, kH = 1080;
  const int tilesX = (kW + raster::kTileSize - 1) / raster::kTileSize;
  const int tilesY = (kH + raster::kTileSize - 1) / raster::kTileSize;
  std::mt19937 rng(7);
  std::vector<uint16_t> color(size_t(tilesX) * tilesY * raster::kTilePixels * 3);
  for (size_t i = 0; i < color.size(); ++i) color[i] = uint16_t(i / 7 % 50000 + rng() % 256);
  const output::GammaTable gamma = output::GammaTable::srgb();
  Image image;
  output::prepareImage(kW, kH, image);
  for (auto _ : state) {
    for (int t = 0; t < tilesX * tilesY; ++t)
      output::resolveTile(color.data() + size_t(t) * raster::kTilePixels * 3, t % tilesX,
                          t / tilesX, gamma, image);
    benchmark::DoNotOptimize(image.rgb.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * int64_t(kW) * kH);
}
BENCHMARK(BM_ResolveFrame);

// The traversal stage over BENCH.md's city (110 001 instances) from its camera, 1 thread: the
// instance tree classified, every instance's level chosen; argument 1: through the tree, 0: every
// instance tested on its own.
void BM_TraverseCity(benchmark::State& state) {
  scene::Scene city = generators::generateCity({});
  if (!state.range(0)) city.instanceTree.reset();
  RenderOptions o;
  o.width = 1920;
  o.height = 1080;
  const render::FrameCamera camera = render::chooseCamera(city, o).value();
  std::vector<std::array<Vec3, 2>> bounds;
  for (const scene::Mesh& m : city.meshes) bounds.push_back(m.bounds());
  core::ThreadPool pool(1);
  traversal::Traversal t;
  for (auto _ : state) {
    traversal::traverse(city, render::traversalOptions(o), render::traversalView(camera), bounds,
                        pool, t);
    benchmark::DoNotOptimize(t.draws.data());
  }
  state.counters["instances/s"] = benchmark::Counter(
      double(city.instances.size()) * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["draws"] = double(t.draws.size());
}
BENCHMARK(BM_TraverseCity)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace sv

BENCHMARK_MAIN();
