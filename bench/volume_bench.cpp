// Kernel benchmarks of the volume pass's per-sample work (issue 59's cost model, docs/volumes.md):
//   the sample kernel (volume/sample_kernel.h) on a 256³ 8-bit grid, 16 samples a call along rays
//   through it half a voxel apart, as the pass feeds it — unlit from the plain codes, lit from the
//   bordered codes' cross (8-bit, as `bench volume`), lit from 16-bit codes, and unlit from the
//   8-bit cross (the pass's way for 8-bit data)                                     → ns a sample
//   the front-to-back compositing of the classified samples as the pass does it (scalar, double,
//   in order, stopping at a transparency of 1/512)                                  → ns a sample
// The two together are the pass's cost a sample before its walk and bookkeeping; the frame's
// budget a sample is in docs/volumes.md. Run: build/bench/sv_volume_bench (SV_BENCH_TARGET=avx2
// for the AVX2 kernels on an AVX-512 machine).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "bench_target.h"
#include "volume/sample_kernel.h"

namespace {

using sv::volume::kBatch;
using sv::volume::SampleBatch;
using sv::volume::SampleSource;

constexpr int kN = 256;  // samples a side, unit spacing

// A 256³ grid of blobs (a smooth density, about 70 % of it below the table's first opaque entry,
// as BENCH.md's `volume`), its bordered copies and a transfer table of 256 entries.
struct Grid {
  std::vector<uint16_t> codes, padded;
  std::vector<uint8_t> padded8;
  std::vector<float> table, stepOpacity;

  Grid() {
    codes.resize(size_t(kN) * kN * kN);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0, 1);
    float blobs[24][4];
    for (auto& b : blobs)
      b[0] = kN * u(rng), b[1] = kN * u(rng), b[2] = kN * u(rng), b[3] = 20 + 30 * u(rng);
    for (int k = 0; k < kN; ++k)
      for (int j = 0; j < kN; ++j)
        for (int i = 0; i < kN; ++i) {
          float v = 0;
          for (const auto& b : blobs) {
            const float dx = i - b[0], dy = j - b[1], dz = k - b[2];
            v += std::exp(-(dx * dx + dy * dy + dz * dz) / (b[3] * b[3]));
          }
          codes[(size_t(k) * kN + size_t(j)) * kN + size_t(i)] =
              uint16_t(std::min(255.0f, 200 * v));
        }
    const int p = kN + 2;
    padded.resize(size_t(p) * p * p);
    for (int k = 0; k < p; ++k)
      for (int j = 0; j < p; ++j)
        for (int i = 0; i < p; ++i)
          padded[(size_t(k) * p + size_t(j)) * p + size_t(i)] =
              codes[(size_t(std::clamp(k - 1, 0, kN - 1)) * kN +
                     size_t(std::clamp(j - 1, 0, kN - 1))) *
                        kN +
                    size_t(std::clamp(i - 1, 0, kN - 1))];
    padded8.assign(padded.size() + 4, 0);
    for (size_t i = 0; i < padded.size(); ++i) padded8[i] = uint8_t(padded[i]);
    table.resize(256 * 4);
    stepOpacity.resize(256);
    for (int e = 0; e < 256; ++e) {
      const float o = e < 60 ? 0.0f : 0.02f + 0.3f * float(e - 60) / 195;
      table[size_t(e) * 4 + 0] = 0.9f, table[size_t(e) * 4 + 1] = float(e) / 255;
      table[size_t(e) * 4 + 2] = 0.4f, table[size_t(e) * 4 + 3] = o;
      stepOpacity[size_t(e)] = 1 - std::pow(1 - o, 0.5f);  // a step of half a voxel
    }
  }

  SampleSource source(int mode) const {
    SampleSource s;
    s.codes = codes.data();
    s.nx = s.ny = s.nz = kN;
    s.table = table.data();
    s.entries = 256;
    s.codeScale = 1;
    s.stepOpacity = stepOpacity.data();
    s.shade = mode == 1 || mode == 2;
    if (mode == 1 || mode == 3) s.padded8 = padded8.data();
    if (mode == 2) s.padded = padded.data();
    for (int a = 0; a < 3; ++a) s.toWorld[a][a] = 1;
    s.toLight[0] = 0.48f, s.toLight[1] = 0.6f, s.toLight[2] = -0.64f;
    return s;
  }
};

const Grid& grid() {
  static const Grid g;
  return g;
}

// Positions along 4 096 rays across the grid, half a voxel apart: the samples of the pass's order.
std::vector<float> rayPositions() {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0, 1);
  std::vector<float> xyz;
  for (int r = 0; r < 4096; ++r) {
    const float y = 8 + (kN - 16) * u(rng), z = 8 + (kN - 16) * u(rng);
    const float dy = 0.3f * (u(rng) - 0.5f), dz = 0.3f * (u(rng) - 0.5f);
    for (float x = 0.25f; x < kN - 1; x += 0.5f) {
      const float t = x;
      xyz.insert(xyz.end(), {x, std::clamp(y + t * dy, 0.0f, kN - 1.0f),
                             std::clamp(z + t * dz, 0.0f, kN - 1.0f)});
    }
  }
  return xyz;
}

void BM_VolumeClassify(benchmark::State& state) {
  const SampleSource source = grid().source(int(state.range(0)));
  static const std::vector<float> xyz = rayPositions();
  const size_t samples = xyz.size() / 3;
  SampleBatch batch;
  size_t at = 0, done = 0;
  for (auto _ : state) {
    for (int l = 0; l < kBatch; ++l, at = (at + 1) % samples) {
      batch.x[l] = xyz[at * 3], batch.y[l] = xyz[at * 3 + 1], batch.z[l] = xyz[at * 3 + 2];
    }
    sv::volume::classifySamples(source, kBatch, batch);
    benchmark::DoNotOptimize(batch.r[0]);
    done += kBatch;
  }
  state.counters["ns/sample"] =
      benchmark::Counter(double(done), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  static const char* const kLabels[] = {"unlit, the plain codes", "lit, 8-bit cross",
                                        "lit, 16-bit cross", "unlit, 8-bit cross"};
  state.SetLabel(kLabels[state.range(0)]);
}
BENCHMARK(BM_VolumeClassify)->Arg(0)->Arg(1)->Arg(2)->Arg(3);

// The pass's compositing of a classified batch (volume_pass.cpp, castStretch's flush): full steps
// with their tabled opacity, colour over the running transparency in double, in ray order.
void BM_VolumeComposite(benchmark::State& state) {
  const SampleSource source = grid().source(1);
  static const std::vector<float> xyz = rayPositions();
  const size_t samples = xyz.size() / 3;
  // Classified once: the compositing alone is timed.
  std::vector<SampleBatch> batches(samples / kBatch);
  for (size_t b = 0; b < batches.size(); ++b) {
    for (int l = 0; l < kBatch; ++l) {
      const size_t at = b * kBatch + size_t(l);
      batches[b].x[l] = xyz[at * 3], batches[b].y[l] = xyz[at * 3 + 1],
      batches[b].z[l] = xyz[at * 3 + 2];
    }
    sv::volume::classifySamples(source, kBatch, batches[b]);
  }
  const double epsilon = 1.0 / 512;
  double C[3] = {0, 0, 0}, T = 1;
  size_t b = 0, done = 0;
  for (auto _ : state) {
    const SampleBatch& s = batches[b];
    b = (b + 1) % batches.size();
    for (int j = 0; j < kBatch; ++j) {
      if (!(s.opacity[j] > 0)) continue;
      const double w = s.w[j];
      C[0] += T * w * s.r[j], C[1] += T * w * s.g[j], C[2] += T * w * s.b[j];
      T *= 1 - w;
      if (T < epsilon) T = 1;  // the next ray
    }
    done += kBatch;
  }
  benchmark::DoNotOptimize(C[0]);
  state.counters["ns/sample"] =
      benchmark::Counter(double(done), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_VolumeComposite);

}  // namespace

int main(int argc, char** argv) { return sv::bench::runBenchmarks(argc, argv, "sv_volume_bench"); }
