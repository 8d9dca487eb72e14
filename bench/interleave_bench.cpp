// Tiles with binning versus SPEC §3.4's sparse-raster interleave, on BENCH.md `tris` scenes at
// 1920×1080 with 2 threads — the measurement behind keeping tiles (docs/performance.md).
//
//   BM_Tiles       the renderer's path: setup and binning in chunks, then 64×64 tiles in parallel.
//   BM_Interleave  a 2×1 processor matrix (seed 000 eqs. 10–13): thread j owns the pixel columns
//                  x ≡ j (mod 2). Each sees a sparse 960×1080 raster and draws *every* triangle on
//                  it, with the edges and parameters re-based as the seed prescribes (steps p·A,
//                  initial values C + j·A). Setup is done once and shared; each thread then bins
//                  its own raster and draws it with the same tile kernel, so the comparison
//                  isolates the decomposition.
// Both fill the same pixels; the interleave's image would need an interleaving resolve (not
// timed here), and its float parameters are evaluated in a different order, so it is not
// bit-identical to the one-thread image as SPEC §6 demands — a second strike against it.
#include <benchmark/benchmark.h>

#include <thread>

#include "bench_scenes.h"
#include "core/check.h"
#include "raster/binner.h"
#include "raster/framebuffer.h"
#include "raster/rasterizer.h"
#include "render/frame_renderer.h"

namespace sv {
namespace {

constexpr int kWidth = 1920, kHeight = 1080;

void BM_Tiles(benchmark::State& state) {
  const render::DrawPackets packets =
      bench::trisPackets(int(state.range(0)), double(state.range(1)), kWidth, kHeight);
  render::FrameRenderer fr(2);
  render::FrameSettings fs;
  fs.width = kWidth;
  fs.height = kHeight;
  FrameStats stats;
  for (auto _ : state) {
    stats = {};
    SV_CHECK(fr.render(packets, fs, stats).ok());
  }
  state.counters["triangles/s"] = benchmark::Counter(
      double(packets.indices.size() / 3) * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["fragments"] = double(stats.fragments);  // equal in both: the same pixels
}

// Re-bases a dense-raster triangle onto the sparse raster of processor (j, k) of a p × q matrix:
// pixel (x, y) = (p·u + j, q·v + k). Returns false if none of its pixels are that processor's.
bool toSparse(const geometry::TriangleSetup& t, int p, int q, int j, int k,
              geometry::TriangleSetup& s) {
  auto ceilDiv = [](int a, int b) { return a >= 0 ? (a + b - 1) / b : -((-a) / b); };
  auto floorDiv = [](int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); };
  const int u0 = ceilDiv(t.minX - j, p), u1 = floorDiv(t.maxX - j, p);
  const int v0 = ceilDiv(t.minY - k, q), v1 = floorDiv(t.maxY - k, q);
  if (u0 > u1 || v0 > v1) return false;
  s = t;
  for (int e = 0; e < t.edgeCount; ++e) {
    // e'(u, v) = (C + A·j + B·k) + p·A·u + q·B·v  (seed 000 eq. 11)
    s.edges[e].c = t.edges[e].c + t.edges[e].stepX() * j + t.edges[e].stepY() * k;
    s.edges[e].a = t.edges[e].a * p;
    s.edges[e].b = t.edges[e].b * q;
  }
  const float ox = float(p * u0 + j - t.minX), oy = float(q * v0 + k - t.minY);
  for (geometry::Plane* pl : {&s.depth, &s.invW, &s.red, &s.green, &s.blue}) {
    pl->c0 = pl->c0 + pl->dx * ox + pl->dy * oy;
    pl->dx *= float(p);
    pl->dy *= float(q);
  }
  s.minX = int16_t(u0);
  s.maxX = int16_t(u1);
  s.minY = int16_t(v0);
  s.maxY = int16_t(v1);
  return true;
}

// One processor of the matrix: all triangles, re-based and drawn on its own sparse raster.
struct SparseProcessor {
  int p, q, j, k, width, height, tilesX, tilesY;
  std::vector<geometry::TriangleSetup> sparse, stored;
  raster::Binner binner;
  raster::Binner::Scratch scratch;
  raster::FrameBuffer fb;
  std::vector<raster::RasterStats> stats;

  SparseProcessor(int p_, int q_, int j_, int k_) : p(p_), q(q_), j(j_), k(k_) {
    width = (kWidth - j + p - 1) / p;
    height = (kHeight - k + q - 1) / q;
    tilesX = (width + raster::kTileSize - 1) >> raster::kTileLog2;
    tilesY = (height + raster::kTileSize - 1) >> raster::kTileLog2;
    fb.resize(width, height);
    stats.resize(size_t(tilesX) * tilesY);
  }

  void draw(const std::vector<geometry::TriangleSetup>& dense) {
    sparse.resize(dense.size());
    stored.resize(dense.size());
    uint32_t n = 0;
    for (const auto& t : dense) n += toSparse(t, p, q, j, k, sparse[n]);
    binner.reset(1, tilesX, tilesY);
    binner.binChunk(0, sparse.data(), n, stored.data(), 0, scratch);
    for (int tile = 0; tile < tilesX * tilesY; ++tile) {
      const raster::Binner::List list = binner.list(0, tile);
      const uint32_t* lists[1] = {list.data};
      const uint32_t sizes[1] = {list.size};
      raster::TileWork w;
      w.tileX = tile % tilesX;
      w.tileY = tile / tilesX;
      w.depth = fb.tileDepth(tile);
      w.color = fb.tileColor(tile);
      w.clear = true;
      w.setups = stored.data();
      w.lists = lists;
      w.listSizes = sizes;
      w.listCount = 1;
      raster::rasterizeTile(w, stats[tile]);
    }
  }
};

void BM_Interleave(benchmark::State& state) {
  const render::DrawPackets packets =
      bench::trisPackets(int(state.range(0)), double(state.range(1)), kWidth, kHeight);
  const geometry::Viewport viewport{kWidth, kHeight};
  const size_t count = packets.indices.size() / 3;
  std::vector<geometry::TriangleSetup> dense(count);
  std::vector<uint32_t> drawn(2);
  SparseProcessor proc[2] = {{2, 1, 0, 0}, {2, 1, 1, 0}};
  for (auto _ : state) {
    // Setup once, split between the two threads; then each draws everything on its raster.
    std::vector<geometry::TriangleSetup> halves[2];
    auto work = [&](int id) {
      const size_t begin = count * id / 2, end = count * (id + 1) / 2;
      auto& out = halves[id];
      out.clear();
      for (size_t t = begin; t < end; ++t) {
        const uint32_t* idx = &packets.indices[t * 3];
        geometry::TriangleSetup s;
        if (geometry::setupTriangle(packets.vertices[idx[0]], packets.vertices[idx[1]],
                                    packets.vertices[idx[2]], viewport, geometry::CullMode::none,
                                    s) == geometry::SetupOutcome::drawn)
          out.push_back(s);
      }
    };
    std::thread other(work, 1);
    work(0);
    other.join();
    dense = halves[0];
    dense.insert(dense.end(), halves[1].begin(), halves[1].end());
    std::thread second([&] { proc[1].draw(dense); });
    proc[0].draw(dense);
    second.join();
  }
  uint64_t fragments = 0;
  for (auto& pr : proc)
    for (auto& st : pr.stats) fragments += st.fragments;
  state.counters["fragments"] = double(fragments) / double(state.iterations());
  state.counters["triangles/s"] =
      benchmark::Counter(double(count) * state.iterations(), benchmark::Counter::kIsRate);
}

BENCHMARK(BM_Tiles)
    ->Args({100000, 10})
    ->Args({10000, 1000})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_Interleave)
    ->Args({100000, 10})
    ->Args({10000, 1000})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace sv

BENCHMARK_MAIN();
